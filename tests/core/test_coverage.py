"""A closure mix's transparency as coverage (reflectance/coverage.py): the drawn surface's weights times the
coverage are the mix's weights again, exactly for numbers and per pixel for textures."""
import numpy as np

from sg_prt_addon.reflectance import coverage
from sg_prt_addon.reflectance.texture_expression import Expression


def test_numbers_divide_by_the_coverage():
    weights, alpha = coverage.drawn_weights([0.3, 0.2], 0.5)
    assert alpha == 0.5 and weights == [0.6, 0.4]
    assert coverage.drawn_weights([0.7], 0.0) == ([0.7], 1.0)       # nothing transparent: unchanged
    weights, alpha = coverage.drawn_weights([0.0], 1.0)              # all transparent: nothing is drawn
    assert alpha == 0.0 and weights == [0.0]


def test_a_weight_that_is_the_coverage_becomes_one():
    """Principled Alpha a: the BSDF weighs a, the transparency 1 - a, the coverage a: the BSDF is drawn whole
    (its colours keep the plain image path, not a division per pixel)."""
    a = Expression.image("alpha_map")
    weights, alpha = coverage.drawn_weights([a, 0.5 * a], Expression.constant(1.0) - a)
    assert weights == [1.0, 0.5]
    assert alpha.terms[0][1][0].function.name == "clamp"


def test_textured_weights_times_the_coverage_are_the_mix_per_pixel():
    """A Mix Shader by a texture f of an Emission e (weight 1 - f) and a Transparent BSDF at g (weight f g) beside
    an Add Shader's Diffuse (weight 1): per pixel, coverage x drawn weight = weight, where the coverage is
    above 0."""
    f, g = Expression.image("f"), Expression.image("g")
    weights = [1.0 - f, Expression.constant(0.25)]
    drawn, alpha = coverage.drawn_weights(weights, f * g)
    rng = np.random.default_rng(2)
    samples = {"f": rng.uniform(0.0, 1.0, (500, 3)), "g": rng.uniform(0.0, 1.0, (500, 3))}
    covered = alpha.values(samples)
    assert np.all((covered >= 0.0) & (covered <= 1.0))
    np.testing.assert_allclose(covered, 1.0 - samples["f"] * samples["g"], rtol=1e-6)
    for weight, drawn_weight in zip(weights, drawn):
        expected = np.broadcast_to(Expression.of(weight).values(samples), covered.shape)
        np.testing.assert_allclose(covered * Expression.of(drawn_weight).values(samples), expected, rtol=2e-6,
                                   atol=1e-7)
