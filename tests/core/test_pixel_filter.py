"""The pixel filter (engine/pixel_filter.py): Cycles' Box, Gaussian and Blackman-Harris at the film's Filter
Size; the jittered frames' offsets drawn from it; Edges Only's grid of samples weighted by it, measured against
the filtered image by dense quadrature."""
import numpy as np
import pytest

from benchmarks.accuracy import film
from sg_prt_addon.engine import anti_aliasing
from sg_prt_addon.engine.pixel_filter import MAX_RADIUS, PixelFilter, filter_supersampled

FILTERS = (PixelFilter("BOX", 1.0), PixelFilter("GAUSSIAN", 1.5), PixelFilter("BLACKMAN_HARRIS", 1.5),
           PixelFilter("BLACKMAN_HARRIS", 2.5))


def _integral(values, x, axis=-1):
    """The trapezoid rule along ``axis`` (numpy 1 and 2 name theirs differently)."""
    values = np.moveaxis(np.asarray(values), axis, -1)
    return np.sum(0.5 * (values[..., 1:] + values[..., :-1]) * np.diff(x), axis=-1)


def _dense(pixel_filter, count=200001):
    x = np.linspace(-pixel_filter.radius, pixel_filter.radius, count)
    density = pixel_filter.weight(x)
    return x, density / _integral(density, x)


def test_profiles_are_cycles():
    """intern/cycles/scene/film.cpp: Blackman-Harris spans +-width (1 at the centre, 6e-5 at its ends); the
    Gaussian's sigma is width / 4, cut at 1.5 width; the Box covers +-width / 2."""
    harris = PixelFilter("BLACKMAN_HARRIS", 1.5)
    assert harris.weight(0.0) == pytest.approx(1.0, abs=1e-12)
    assert harris.weight(1.5) == pytest.approx(6e-5, abs=1e-6) and harris.weight(1.5001) == 0.0
    assert harris.radius == 1.5 and harris.reach == 1
    assert PixelFilter("GAUSSIAN", 1.5).variance() == pytest.approx((1.5 / 4) ** 2, rel=1e-4)
    assert PixelFilter("GAUSSIAN", 1.5).radius == 2.25
    box = PixelFilter("BOX", 1.0)
    assert box.variance() == pytest.approx(1.0 / 12.0, rel=1e-5) and box.reach == 0
    assert box.footprint_side() == pytest.approx(1.0, rel=1e-5)     # a 1-pixel box shades the whole pixel
    assert harris.footprint_side() == pytest.approx(np.sqrt(12.0 * harris.variance()))
    with pytest.raises(ValueError, match="unknown pixel filter"):
        PixelFilter("LANCZOS", 1.0)


def test_a_filter_wider_than_the_engine_reaches_is_cut():
    wide = PixelFilter("BLACKMAN_HARRIS", 5.0)
    assert wide.truncated and wide.radius == MAX_RADIUS and wide.reach == 3
    assert not PixelFilter("BLACKMAN_HARRIS", 3.0).truncated
    # the profile keeps its width: cut, not squeezed
    assert wide.weight(1.0) == pytest.approx(PixelFilter("BLACKMAN_HARRIS", 5.0 - 1e-9).weight(1.0))


def test_a_one_pixel_box_weighs_every_frame_alike():
    """The 1-pixel Box: the frames' offsets are the strata and each frame's pixel weighs 1 / frames, so Render
    Samples of every pixel equal a render that many times larger box-filtered down
    (tests/gpu/test_render_samples.py)."""
    box = PixelFilter("BOX", 1.0)
    strata = anti_aliasing.pixel_jitter(16)
    np.testing.assert_allclose(box.jitter_offsets(strata), strata)
    weights = box.frame_weights(strata)
    assert weights.shape == (16, 2, 1)
    np.testing.assert_allclose(weights[:, 0, 0] * weights[:, 1, 0], 1.0 / 16)
    np.testing.assert_allclose(box.grid_weights(4), [0.25] * 4)


@pytest.mark.parametrize("pixel_filter", FILTERS, ids=lambda f: f"{f.kind}-{f.width}")
def test_frame_weights_are_the_filter_at_each_sample(pixel_filter):
    """Each frame's pixel k away weighs f(k + offset) along each axis; over the frames and neighbours they make 1;
    a filter narrower than a pixel has its strata squeezed into it, so every frame weighs."""
    offsets = pixel_filter.jitter_offsets(anti_aliasing.pixel_jitter(7))
    weights = pixel_filter.frame_weights(offsets)
    reach = pixel_filter.reach
    assert weights.shape == (7, 2, 2 * reach + 1)
    assert np.sum(weights[:, 0].sum(axis=1) * weights[:, 1].sum(axis=1)) == pytest.approx(1.0)
    neighbours = np.arange(-reach, reach + 1)[None, :]
    np.testing.assert_allclose(weights[:, 1], pixel_filter.weight(neighbours + offsets[:, 1:2]))
    along_x = pixel_filter.weight(neighbours + offsets[:, 0:1])
    np.testing.assert_allclose(weights[:, 0], along_x * (weights[:, 0].sum() / along_x.sum()))
    narrow = PixelFilter("BOX", 0.2)
    squeezed = narrow.jitter_offsets(anti_aliasing.pixel_jitter(4))
    assert np.abs(squeezed).max() < 0.1 and (narrow.frame_weights(squeezed) > 0).all()


@pytest.mark.parametrize("pixel_filter", FILTERS, ids=lambda f: f"{f.kind}-{f.width}")
def test_grid_weights_sum_to_one_over_the_reach(pixel_filter):
    weights = pixel_filter.grid_weights(4)
    assert weights.shape == ((2 * pixel_filter.reach + 1) * 4,)
    assert weights.sum() == pytest.approx(1.0) and np.allclose(weights, weights[::-1])
    # a filter narrower than a cell: the samples nearest the centre, alike
    np.testing.assert_allclose(PixelFilter("BOX", 0.1).grid_weights(4), [0.0, 0.5, 0.5, 0.0])


def test_edges_only_grid_and_frames_come_close_to_the_filtered_image():
    """Edges Only weights a 4 x 4 grid of samples a pixel by the filter, 16 jittered frames weight the pixels
    around each: against the exactly filtered row (Blackman-Harris 1.5, away from the borders) their error is a
    fraction of a 1-pixel box's, the filter the engine used before (measured: 4 x 4 0.0089, 8 x 8 0.0003, 16
    frames 0.0089, the box of 16 samples 0.095; docs/ACCURACY.md, film)."""
    errors = film.filter_errors()
    print("relative RMSE against the exact Blackman-Harris 1.5: " + ", ".join(f"{k} {v:.4f}" for k, v in errors.items()))
    assert errors["grid 4"] < 0.015 and errors["grid 8"] < 0.001 and errors["frames 16"] < 0.015
    assert errors["box 16"] > 5 * max(errors["grid 4"], errors["frames 16"])


def test_filter_supersampled_keeps_a_constant_and_its_borders():
    image = np.full((12, 20, 3), 0.7)
    for pixel_filter in FILTERS:
        np.testing.assert_allclose(filter_supersampled(image, pixel_filter, 4), np.full((3, 5, 3), 0.7))
