"""wang2009's SG lobes: parametric (sg_parametric) and from a stored lobe fit (sg_fitted), what they share
(sg_lobes: the variant key, the GLSL assembly, the lobe sources), and their numpy mirror (sg_shading,
fitted_texels); shaders/techniques/sg/."""
