"""The SG techniques' Blender side (blender/technique_sides.py): the view warp every SG technique reads
(material.sgprt.sg), and what renders a material that picks the fitted lobes without a usable fit; the lobe fit's
checks the techniques built on these lobes share (isotropic_lobe_fit, lobe_tilt)."""
import bpy
from bpy.props import EnumProperty

from ....biscale import effective_brdf
from ....blender import export, lobe_fit
from ....blender.properties import _tag_changed
from .. import sg_fitted, sg_parametric

# How each NDF lobe is warped to the view slice: spherical.warp's modes, upper case (figures from its docstring).
VIEW_WARPS = (
    ("SPLIT3", "3 Lobes", "Three warped lobes per NDF lobe (default): the most accurate at grazing views "
                          "(mean energy error 0.09 at 75 degrees)"),
    ("SPLIT2", "2 Lobes", "Two warped lobes per NDF lobe: about a fifth faster on anisotropic metals, "
                          "energy error 0.15 at 75 degrees"),
    ("PAPER", "1 Lobe", "The paper's single warped lobe: fastest, loses energy at grazing views "
                        "(0.08 at 75 degrees, 0.2 at 85)"),
)


class SGPRT_PG_sg(bpy.types.PropertyGroup):
    """What every SG technique reads (material.sgprt.sg)."""
    view_warp: EnumProperty(update=_tag_changed, name="View Warp", items=VIEW_WARPS, default="SPLIT3",
                            description="Lobes each NDF lobe becomes in the view slice (wang2009 eq. 17-22 and its "
                                        "split): fewer render faster, more are more accurate at grazing views")


SETTINGS = {"sg": SGPRT_PG_sg}
LEGACY = {"sg": {"view_warp": "view_warp"}}


def draw(layout, material, name):
    layout.prop(material.sgprt.sg, "view_warp")


def read(material, params):
    params.warp_mode = material.sgprt.sg.view_warp.lower()       # VIEW_WARPS: spherical.warp's mode names


def resolve(material, params, name):
    if name == sg_fitted.NAME:
        return _resolve_fitted(material, params)
    return name, []


def _resolve_fitted(material, params):
    params.fitted = export.export_fitted_lobes(material)
    if params.fitted is None:
        state, message = lobe_fit.fit_status(material)
        return sg_parametric.NAME, [f"material '{material.name}': no usable lobe fit ({message or state.lower()}): "
                                    "rendered with its model"]
    return sg_fitted.NAME, []


def isotropic_lobe_fit(material):
    """(FittedLobes, None) of the material's stored fit when its lobes lie about the normal (a small-scale BRDF
    must be isotropic), else (None, the reason)."""
    fitted = export.export_fitted_lobes(material)
    if fitted is None:
        state, message = lobe_fit.fit_status(material)
        return None, message or state.lower()
    reason = lobe_tilt(fitted)
    if reason is not None:
        return None, reason + " for an isotropic small-scale BRDF"
    return fitted, None


def lobe_tilt(fitted):
    """Why a FittedLobes is not isotropic (its lobes leave the normal: a free-axes fit), or None."""
    tilt, degrees = effective_brdf.axis_tilt(fitted.layers[1:1 + 2 * fitted.lobe_count:2, ..., :3])
    if tilt > effective_brdf.AXIS_TOLERANCE:
        return f"its lobes leave the normal by up to {degrees:.1f} degrees: fit with Axes Auto"
    return None


def lobe_fit_use(material, name):
    if name == sg_fitted.NAME:
        return ""
    return None


