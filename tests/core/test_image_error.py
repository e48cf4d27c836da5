import numpy as np
import pytest

from validation import image_error


def test_scores_of_known_differences():
    reference = np.full((4, 4, 3), 2.0)
    assert image_error.relative_rmse(reference, reference) == 0.0
    assert image_error.relative_rmse(reference * 1.1, reference) == pytest.approx(0.1)
    assert image_error.relative_mean_bias(reference * 0.9, reference) == pytest.approx(-0.1)
    noise = np.full((4, 4, 3), 0.02)
    assert image_error.rmse_noise_floor(noise, reference) == pytest.approx(0.01)
    mask = np.zeros((4, 4), bool)
    mask[0, 0] = True
    shifted = reference.copy()
    shifted[1:] += 5
    assert image_error.relative_rmse(shifted, reference, mask) == 0.0


def test_bad_input_is_named():
    with pytest.raises(ValueError, match="differ in shape"):
        image_error.relative_rmse(np.zeros((2, 2, 3)), np.zeros((3, 2, 3)))
    broken = np.ones((2, 2, 3))
    broken[0, 0, 1] = np.nan
    with pytest.raises(ValueError, match="1 pixels are not finite"):
        image_error.relative_rmse(broken, np.ones((2, 2, 3)))
