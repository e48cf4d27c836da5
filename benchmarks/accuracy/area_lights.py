"""Accuracy of area lights as patches (lighting.lights.area_light_patches): the irradiance the engine's shading
gives from a square light cut into n x n patches (each a sphere light's SG with its one-sided cosine and spread,
against the clamped cosine) against Lambert's exact polygon formula, and with a narrowed spread against
quadrature over the light's area.  Receivers: 300 points spread under the unit square at a distance, their
normals up to 70 degrees off its direction."""
import numpy as np

from sg_prt_addon.lighting import lights
from validation import exact_references

CENTRE = np.zeros(3)
EDGE_U, EDGE_V = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
DOWN = np.array([0.0, 0.0, -1.0])
# corners of the unit square turning anticlockwise about DOWN (the side polygon_irradiance lights)
CORNERS = np.array([[-0.5, -0.5, 0.0], [-0.5, 0.5, 0.0], [0.5, 0.5, 0.0], [0.5, -0.5, 0.0]])


def _receivers(distance, count=300, seed=1):
    rng = np.random.default_rng(seed)
    position = np.c_[rng.uniform(-1.0, 1.0, count), rng.uniform(-1.0, 1.0, count), np.full(count, -distance)]
    normal = rng.normal(size=(count, 3))
    normal[:, 2] = np.abs(normal[:, 2]) + 0.4
    return position, normal / np.linalg.norm(normal, axis=-1, keepdims=True)


def _errors(value, reference):
    """(relative L2, max relative error over points receiving over 1% of the largest irradiance)."""
    lit = reference > 0.01 * reference.max()
    relative = np.abs(value - reference)[lit] / reference[lit]
    return float(np.sqrt(np.mean((value - reference) ** 2) / np.mean(reference ** 2))), float(relative.max())


def measure():
    rows = []
    for per_side in (1, 2, 4, 6):
        for distance in (0.25, 0.5, 1.0, 2.0):
            position, normal = _receivers(distance)
            patches = lights.area_light_patches(CENTRE, EDGE_U, EDGE_V, DOWN, "SQUARE", np.array([np.pi]), per_side)
            value = lights.patches_irradiance(position, normal, patches)[:, 0]
            l2, largest = _errors(value, lights.polygon_irradiance(position, normal, CORNERS))
            rows.append(dict(name=f"area light, {per_side} x {per_side} patches, {distance:g} light sizes away",
                             reference="Lambert's polygon formula (clipped to the receiver's horizon)",
                             metric="irradiance relative L2 (mean column); max relative where over 1% of peak",
                             max_error=largest, mean_error=l2,
                             note="the default is 4 x 4 (scene.sgprt.area_light_patches)" if per_side == 4 else ""))
    for spread in (90.0, 60.0, 30.0):
        position, normal = _receivers(1.0, count=60)
        patches = lights.area_light_patches(CENTRE, EDGE_U, EDGE_V, DOWN, "SQUARE", np.array([np.pi]), 4,
                                            spread=np.radians(spread))
        value = lights.patches_irradiance(position, normal, patches)[:, 0]
        reference = exact_references.area_irradiance_quadrature(position, normal, CENTRE, EDGE_U, EDGE_V, DOWN,
                                                      np.radians(spread))
        l2, largest = _errors(value, reference)
        rows.append(dict(name=f"area light, 4 x 4 patches, spread {spread:g} degrees, 1 light size away",
                         reference="midpoint rule over the light's area, 400 x 400",
                         metric="irradiance relative L2 (mean column); max relative where over 1% of peak",
                         max_error=largest, mean_error=l2,
                         note="the attenuation taken at each patch's centre; export warns below 30 degrees"))
    return rows
