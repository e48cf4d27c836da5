"""What checks the engine and is not shipped with it: the Monte Carlo reference renderer, environment
sampling, image scores, test cameras, BRDF data generators, the reference-scene export, the GLSL harness
and the derivation of frozen fits.  Tests and benchmarks import it; the extension zip leaves it out."""
