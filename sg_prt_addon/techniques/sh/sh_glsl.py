"""The generated part of the SH technique's GLSL: the constants of an order and window (normalization,
window factors, the clamped cosine's A_l, the indices a lobe fit's table stores: harmonics.fitted_table) and
the two fixed x rotations of the zyz method unrolled over
their non-zero entries (harmonics.rotation.x90_blocks), so the shader does exactly the numpy's sums."""
import math

from ...harmonics import basis, fitted_table, projection, rotation
from ...reflectance import brdf


def _floats(values):
    return ", ".join(f"{float(v):.9e}" for v in values)


def _x90_function(name, order, transpose):
    lines = [f"void {name}(inout float c[SH_COUNT])", "{", "  float r[SH_COUNT];"]
    for band, block in enumerate(rotation.x90_blocks(order)):
        matrix = block.T if transpose else block
        start = band * band
        for row in range(len(matrix)):
            terms = [f"{matrix[row, col]:.9e} * c[{start + col}]" for col in range(len(matrix)) if matrix[row, col]]
            lines.append(f"  r[{start + row}] = " + (" + ".join(terms) if terms else "0.0") + ";")
    lines += ["  c = r;", "}"]
    return "\n".join(lines)


def constants_source(order, window):
    """GLSL defines, constant arrays and sh_rotate_x90 / sh_rotate_x90_inverse of an order (2-8) and window
    ("none", None or one of harmonics.projection.WINDOWS)."""
    normalization = [basis.normalization(band, m) * (math.sqrt(2.0) if m else 1.0)
                     for band in range(order) for m in range(band + 1)]
    cosine = projection.clamped_cosine_zonal(order) / [basis.normalization(band, 0) for band in range(order)]
    stored = fitted_table.positive_m_indices(order)
    parts = [f"#define SH_ORDER {order}", f"#define SH_COUNT {order * order}",
             f"const float SH_NORMALIZATION[{len(normalization)}] = float[]({_floats(normalization)});",
             f"const float SH_WINDOW[SH_ORDER] = float[]({_floats(projection.window_factors(window, order))});",
             "/* A_l: the clamped cosine's bands (Ramamoorthi and Hanrahan 2001) */",
             f"const float SH_COSINE[SH_ORDER] = float[]({_floats(cosine)});",
             f"#define SH_STORED {len(stored)}",
             "/* a lobe fit's table stores the m >= 0 coefficients (l, then m = 0 .. l): their indices */",
             f"const int SH_STORED_INDEX[SH_STORED] = int[]({', '.join(str(i) for i in stored)});",
             f"const float SH_COSINE_EPSILON = {brdf.COSINE_EPSILON:.9e};      /* brdf.COSINE_EPSILON */",
             _x90_function("sh_rotate_x90", order, False), _x90_function("sh_rotate_x90_inverse", order, True)]
    return "\n".join(parts) + "\n"
