"""iwasaki2012's bi-scale materials: small-scale geometry (microgeometry), its BVNDF as SGs (spherical_em,
bvndf) and the effective BRDF they make with a small-scale BRDF (effective_brdf).  Pure numpy (and embreex
through visibility.raytrace)."""
