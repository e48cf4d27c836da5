"""A mixture of normalized SGs (von Mises-Fisher lobes) fitted to weighted directions by spherical EM: the
NDF fit of iwasaki2012 eq. 6, by the algorithm it cites (Han et al. 2007, after Banerjee et al. 2005).

A normalized lobe is G(n; axis, sharpness, c(sharpness)) with c = sharpness / (2 pi (1 - e^-2 sharpness)), so
that it integrates to 1 over the sphere; the mixture is sum_j weight_j G_j, weights summing to 1.
"""
import numpy as np

from ..spherical import sg

# A lobe whose directions all agree (a flat facet) has an unbounded sharpness; the cap keeps it an SG the
# shaders evaluate in float32 (0.2 degree wide), and its convolution with a small-scale lobe of sharpness s
# within s / MAX_SHARPNESS of the small-scale lobe itself.
MAX_SHARPNESS = 1.0e5
MIN_SHARPNESS = 1.0e-3
DEFAULT_ITERATIONS = 60
KMEANS_ROUNDS = 8


def normalization(sharpness):
    """c(sharpness): the amplitude that makes G integrate to 1 over the sphere."""
    return 1.0 / sg.sphere_integral(np.asarray(sharpness, np.float64))


def sharpness_from_mean_length(mean_length):
    """Banerjee et al.'s estimate of the sharpness from the mean resultant length r: r (3 - r^2) / (1 - r^2)."""
    r = np.clip(np.asarray(mean_length, np.float64), 0.0, 1.0 - 1e-12)
    return np.clip(r * (3.0 - r * r) / (1.0 - r * r), MIN_SHARPNESS, MAX_SHARPNESS)


def _initial_axes(directions, weights, lobes):
    """Deterministic seeds: the weighted mean direction's nearest sample, then the sample farthest (by
    weighted angle) from every seed so far; repeated directions fill what is left."""
    mean = sg.normalize(weights @ directions)
    chosen = [int(np.argmax(directions @ mean))]
    closest = directions @ directions[chosen[0]]
    for _ in range(1, lobes):
        score = (1.0 - closest) * np.sqrt(weights)
        candidate = int(np.argmax(score))
        if score[candidate] <= 0:
            candidate = chosen[-1]
        chosen.append(candidate)
        closest = np.maximum(closest, directions @ directions[candidate])
    return directions[chosen].copy()


def _k_means(directions, weights, axes, rounds=KMEANS_ROUNDS):
    """Spherical k-means from the seeds, then each cluster's weight, mean axis and sharpness: EM started from
    broad, overlapping lobes falls into the fixed point where every lobe is the whole distribution's."""
    for _ in range(rounds):
        label = np.argmax(directions @ axes.T, axis=1)
        resultant = np.zeros_like(axes)
        np.add.at(resultant, label, weights[:, None] * directions)
        length = np.linalg.norm(resultant, axis=1)
        axes = np.where(length[:, None] > 0, resultant / np.maximum(length, 1e-300)[:, None], axes)
    mass = np.bincount(label, weights, minlength=len(axes))
    sharpness = np.where(mass > 0, sharpness_from_mean_length(length / np.maximum(mass, 1e-300)), MAX_SHARPNESS)
    return axes, sharpness, np.maximum(mass, 1e-6) / np.maximum(mass, 1e-6).sum()


def fit(directions, weights, lobes, iterations=DEFAULT_ITERATIONS, tolerance=1e-7):
    """Fit lobes to unit directions (N, 3) with weights (N,) >= 0: (axes (J, 3), sharpness (J,), mixture
    weights (J,) summing to 1).  Deterministic; a lobe left with no weight is dropped by giving it weight 0."""
    directions = np.asarray(directions, np.float64).reshape(-1, 3)
    weights = np.asarray(weights, np.float64).reshape(-1)
    if lobes < 1:
        raise ValueError("an NDF fit needs at least one lobe")
    keep = weights > 0
    directions, weights = directions[keep], weights[keep]
    if not len(weights):
        raise ValueError("no directions with positive weight to fit")
    weights = weights / weights.sum()
    axes, sharpness, mixture = _k_means(directions, weights, _initial_axes(directions, weights, lobes))
    previous = -np.inf
    for _ in range(iterations):
        # E step in logs: log(weight_j c_j) + sharpness_j (n . axis_j - 1)
        log_density = (np.log(np.maximum(mixture, 1e-300)) + np.log(normalization(sharpness)))[None, :] + \
            sharpness[None, :] * (directions @ axes.T - 1.0)
        peak = log_density.max(axis=1, keepdims=True)
        responsibility = np.exp(log_density - peak)
        total = responsibility.sum(axis=1, keepdims=True)
        likelihood = float(weights @ (np.log(total[:, 0]) + peak[:, 0]))
        responsibility *= weights[:, None] / total
        # M step: weight, mean direction and its resultant length per lobe
        mass = responsibility.sum(axis=0)
        resultant = responsibility.T @ directions
        length = np.linalg.norm(resultant, axis=1)
        live = mass > 1e-12
        mixture = np.where(live, mass, 0.0)
        mixture /= mixture.sum()
        axes = np.where(live[:, None] & (length[:, None] > 0), resultant / np.maximum(length, 1e-300)[:, None], axes)
        sharpness = np.where(live, sharpness_from_mean_length(length / np.maximum(mass, 1e-300)), sharpness)
        if likelihood - previous < tolerance * max(1.0, abs(likelihood)):
            break
        previous = likelihood
    return axes, sharpness, mixture


def evaluate(direction, axes, sharpness, mixture):
    """The fitted density at directions (..., 3)."""
    return sg.mixture_evaluate(direction, axes, sharpness, mixture * normalization(sharpness))
