"""A surface's transparency (Transparent BSDF, Principled Alpha) as coverage, the way the engine draws it.

Cycles shades a pixel as the opaque closures' light, weighted as the shaders mix them, plus T times what is
behind (T: the transparent closures' weight).  The engine draws the surface over a fraction c = 1 - T of each
pixel's samples (dithered coverage: shaders/techniques/common/surface_io.glsl) and what is behind over the
rest, so the surface it draws must carry the opaque closures' weights divided by c: c x (w / c) is w again.
A holdout's weight H is divided alike: the drawn surface's alpha is 1 - H / c, and the pixel's 1 - T - H.
"""
from .texture_expression import Expression


def _constant(expression):
    value = expression.as_constant()
    return None if value is None else value[0]


def _clamped(value):
    return Expression.function("clamp", ("MINMAX",), (value, 0.0, 1.0))


def _ratio(weight, coverage):
    """weight / coverage: a number where both are numbers or weight is k x coverage; else an Expression (Math's
    safe divide where coverage is not a number: 0 where it is 0, where no sample is drawn)."""
    weight, coverage = Expression.of(weight), Expression.of(coverage)
    a, b = _constant(weight), _constant(coverage)
    if b is not None:
        if b <= 0.0:
            return 0.0
        return a / b if a is not None else weight * (1.0 / b)
    first_weight, first_coverage = weight.terms[0][0][0], coverage.terms[0][0][0]
    if first_coverage != 0.0:
        k = first_weight / first_coverage
        if (weight - coverage * k).as_constant() == (0.0, 0.0, 0.0):
            return k
    return Expression.function("math", ("DIVIDE",), (weight, coverage, 0.0))


def drawn_weights(weights, transparency):
    """The opaque closures' `weights` (numbers or Expressions) as the drawn surface carries them (each divided
    by the coverage 1 - transparency), and the coverage clamped to [0, 1] (a number or an Expression)."""
    transparency = Expression.of(transparency)
    if transparency.as_constant() == (0.0, 0.0, 0.0):
        return list(weights), 1.0
    coverage = Expression.constant(1.0) - transparency
    constant = _constant(coverage)
    clamped = min(max(constant, 0.0), 1.0) if constant is not None else _clamped(coverage)
    return [_ratio(weight, coverage) for weight in weights], clamped
