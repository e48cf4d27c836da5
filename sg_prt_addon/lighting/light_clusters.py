"""Many point lights as fewer: where a scene has more omni point lights than the shader takes, groups of nearby
lights become one sphere light each (lightcuts' representative lights, as one level of a light tree): the
group's intensity summed at its power-weighted centre, its radius the group's spread.  Far from a group (the
usual case for the dim lights that get grouped) its irradiance is its members' within the spread's share;
near it the light is softer than its members.
"""
from dataclasses import dataclass

import numpy as np

KMEANS_ROUNDS = 12


@dataclass
class LightClusters:
    """`labels` (N,): each light's cluster; per cluster (K): position (K, 3), radius (K,), intensity (K, C)."""
    labels: np.ndarray
    position: np.ndarray
    radius: np.ndarray
    intensity: np.ndarray


def cluster_point_lights(position, radius, intensity, count):
    """`count` clusters of omni point lights (position (N, 3), radius (N,), intensity (N, C) radiant intensity):
    power-weighted k-means on their positions, started at the brightest lights.  A cluster's intensity is its
    members' sum, its position their power-weighted mean, its radius the root mean square of their distances from
    it (power-weighted) plus their mean radius."""
    position = np.asarray(position, np.float64).reshape(-1, 3)
    radius = np.asarray(radius, np.float64).reshape(-1)
    intensity = np.asarray(intensity, np.float64).reshape(len(position), -1)
    weight = np.maximum(intensity.sum(axis=1), 0.0) + 1e-12
    count = int(min(max(count, 1), len(position)))
    centres = position[np.argsort(-weight, kind="stable")[:count]].copy()
    labels = None
    for _round in range(KMEANS_ROUNDS):
        distance = np.linalg.norm(position[:, None, :] - centres[None, :, :], axis=2)
        new_labels = np.argmin(distance, axis=1)
        if labels is not None and np.array_equal(new_labels, labels):
            break
        labels = new_labels
        filled = np.bincount(labels, minlength=count) > 0     # a centre left without lights stays where it was
        centres[filled] = _weighted_sums(labels, weight, position, count)[filled] / \
            np.bincount(labels, weights=weight, minlength=count)[filled, None]
    labels = _relabel(labels)
    clusters = labels.max() + 1
    totals = np.bincount(labels, weights=weight, minlength=clusters)
    centre = _weighted_sums(labels, weight, position, clusters) / totals[:, None]
    spread = np.sqrt(np.bincount(labels, weights=weight * np.sum((position - centre[labels]) ** 2, axis=1),
                                 minlength=clusters) / totals)
    mean_radius = np.bincount(labels, weights=weight * radius, minlength=clusters) / totals
    summed = _weighted_sums(labels, np.ones(len(labels)), intensity, clusters)
    return LightClusters(labels, centre, spread + mean_radius, summed)


def _weighted_sums(labels, weight, values, count):
    """(count, D): the sums of weight x values (N, D) over each label."""
    return np.stack([np.bincount(labels, weights=weight * values[:, d], minlength=count)
                     for d in range(values.shape[1])], axis=1)


def _relabel(labels):
    """Labels renumbered 0.. in order of first use (clusters left empty by k-means are gone)."""
    _, first, inverse = np.unique(labels, return_index=True, return_inverse=True)
    order = np.argsort(np.argsort(first))
    return order[inverse.ravel()]
