"""kautz2002's spherical harmonics: the technique (spherical_harmonics), its generated GLSL constants (sh_glsl)
and its numpy mirror (sh_shading); shaders/techniques/sh/."""
