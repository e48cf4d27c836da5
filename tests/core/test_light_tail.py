"""techniques.sg.sg_shading.light_tail: with it, what a point light sees of GGX (the slice lobes plus the tail) is the
model's own rho_s (n.i) over the whole hemisphere of light directions; without it, the lobes' shape error
and the missing theta^-4 glow (benchmarks/accuracy/glossy_tails.py measures the same for the docs)."""

from benchmarks.accuracy import glossy_tails


def test_point_light_sees_the_models_brdf():
    rows = {row["name"]: row for row in glossy_tails._point_light_rows()}
    bounds = {0.1: 0.02, 0.3: 1e-3, 0.5: 1e-4}      # measured max 9.6e-3, 1.1e-4, 9.7e-6
    for roughness, bound in bounds.items():
        with_tail = rows[f"GGX r={roughness} under a point light: slice lobes + light tail"]["max_error"]
        alone = rows[f"GGX r={roughness} under a point light: 2 SG slice lobes alone"]["max_error"]
        assert with_tail < bound, (roughness, with_tail)
        assert alone > 0.3, (roughness, alone)      # measured 2.9, 0.44, 0.35: what the tail corrects
