/* Depth from a light into one tile of the shadow atlas (engine/shadow_pass.py): tile_matrix is the tile's
 * world -> clip (lighting/shadow_maps.py plan). */
void main()
{
  gl_Position = tile_matrix * (model_matrix * vec4(position, 1.0));
}
