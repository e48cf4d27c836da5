"""The spherical-harmonic technique's Blender side (blender/technique_sides.py): its order, window and what it
tabulates (material.sgprt.sh), and what renders a material whose stored lobe fit it cannot tabulate."""
import bpy
from bpy.props import EnumProperty, IntProperty

from ....blender import export, lobe_fit
from ....blender.properties import _tag_changed
from ...sg import sg_fitted
from ...sg.blender import lobe_tilt
from .. import spherical_harmonics

WINDOWS = (("NONE", "None", "The bands as projected (sharpest; rings around small bright lights)"),
           ("HANNING", "Hanning", "(1 + cos(pi l / N)) / 2 per band: the least ringing, the most blur"),
           ("LANCZOS", "Lanczos", "sinc(l / N) per band: less blur than Hanning, more ringing"))
BRDFS = (("MODEL", "Material Model", "The material's model and parameters, tabulated over its parameter axis"),
         ("LOBE_FIT", "Lobe Fit", "The material's stored lobe fit (Fit Lobes: a measured BRDF or SVBRDF, lobes "
                                  "about the normal), tabulated per texel"))


class SGPRT_PG_sh(bpy.types.PropertyGroup):
    """The spherical-harmonic technique's settings (material.sgprt.sh)."""
    order: IntProperty(update=_tag_changed, name="SH Order", default=spherical_harmonics.DEFAULT_ORDER, min=2, max=8,
                       description="Bands of the spherical-harmonic technique (order N: N^2 coefficients; "
                                   "Kautz 2002 used 5): higher follows sharper lights and glossier lobes")
    window: EnumProperty(update=_tag_changed, name="SH Window", items=WINDOWS, default="NONE",
                         description="Smoothing of the lighting's bands against ringing (it blurs)")
    brdf: EnumProperty(update=_tag_changed, name="SH BRDF", items=BRDFS, default="MODEL",
                       description="What the spherical-harmonic technique tabulates")


SETTINGS = {"sh": SGPRT_PG_sh}
LEGACY = {"sh": {"order": "sh_order", "window": "sh_window", "brdf": "sh_brdf"}}


def draw(layout, material, name):
    settings = material.sgprt.sh
    layout.prop(settings, "order")
    layout.prop(settings, "window")
    layout.prop(settings, "brdf")


def read(material, params):
    params.sh_order = int(material.sgprt.sh.order)
    params.sh_window = material.sgprt.sh.window.lower()     # WINDOWS: harmonics.projection's names


def resolve(material, params, name):
    label = spherical_harmonics.TECHNIQUE.label
    warnings = []
    if material.sgprt.sh.brdf == "LOBE_FIT":
        name, warnings = _resolve_lobe_fit(material, params)
        if name != spherical_harmonics.NAME:
            return name, warnings
    ignored = sorted(slot for slot in params.textures if slot not in spherical_harmonics.texture_slots(params))
    if ignored and params.fitted is not None:
        warnings.append(f"material '{material.name}': {label} tabulates the lobe fit: the textures on "
                        f"{', '.join(ignored)} are not applied")
    elif ignored:
        warnings.append(f"material '{material.name}': {label} tabulates the model with uniform "
                        f"{', '.join(ignored)}: those textures are not applied")
    return spherical_harmonics.NAME, warnings


def _resolve_lobe_fit(material, params):
    """SH with the material's stored lobe fit in params.fitted when it can tabulate it; else SH with the model
    (no usable fit) or the fitted SG lobes (a fit SH cannot tabulate: free axes, too large), with the reason."""
    label = spherical_harmonics.TECHNIQUE.label
    fitted = export.export_fitted_lobes(material)
    if fitted is None:
        state, message = lobe_fit.fit_status(material)
        return spherical_harmonics.NAME, [f"material '{material.name}': {label}: no usable lobe fit "
                                          f"({message or state.lower()}): its model is tabulated"]
    params.fitted = fitted
    reason = lobe_tilt(fitted) or spherical_harmonics.fitted_refusal(fitted, params.sh_order)
    if reason is not None:
        return sg_fitted.NAME, [f"material '{material.name}': {label} cannot tabulate its lobe fit ({reason}): "
                                f"rendered with {sg_fitted.TECHNIQUE.label}"]
    return spherical_harmonics.NAME, []


def lobe_fit_use(material, name):
    if material.sgprt.sh.brdf != "LOBE_FIT":
        return "Renders the model: set SH BRDF to Lobe Fit to render the fit"
    if material.sgprt.lobe_fit.free_axes:
        return "Free axes: SH tabulates lobes about the normal only: rendered as SG lobes"
    return "Tabulated per texel by the SH technique"


def take_lobe_fit(material, name):
    material.sgprt.sh.brdf = "LOBE_FIT"                  # an SH material tabulates the fit
    return True
