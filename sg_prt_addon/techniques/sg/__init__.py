"""wang2009's SG lobes: parametric (sg_parametric) and from a stored lobe fit (sg_fitted), what they share
(sg_lobes), their numpy mirror (sg_shading, fitted_texels), and iwasaki2012's bi-scale materials (sg_biscale,
biscale_shading), shaded by the same SG shader (shaders/techniques/sg/)."""
