"""iwasaki2012's bi-scale materials: the technique (sg_biscale), shaded by the SG technique's stages with its own
lobe source (shaders/techniques/biscale/biscale.glsl), and its numpy mirror (biscale_shading)."""
