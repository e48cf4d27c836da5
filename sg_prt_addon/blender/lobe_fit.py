"""Lobe fit operator: a measured BRDF fitted to SG lobes, stored in the .blend (wang2009 section 4.2).

``bpy.ops.sgprt.fit_lobes(filepath=..., lobe_count=2)`` fits the file to the active
material (``context.material``, else the active object's active material):

- a MERL ``.binary`` file (measured.merl.read_merl): homogeneous, one texel (1 x 1 images),
  factorized and fitted by measured.microfacet_fit.fit_merl (about 1 s);
- an SVBRDF table ``.npz`` (measured.svbrdf_table): H x W texels, fitted by fit_lobes.
The kind is told by content (a .npz is a zip: it starts with ``PK``), not by the name.

execute(): synchronous, printing ``[sg-prt] fit 30% ...`` lines (``blender -b``, tests).
invoke(): the file browser when no filepath was given (its confirmation calls execute(),
which then goes modal as invoke() does with a path): a background thread polled by a
timer, with the window manager's progress bar and status text; Esc cancels.  The
thread reads and fits files only: it never touches bpy.  Nothing is written unless the
fit completes: an unreadable, truncated, corrupt or wrong-size file is reported (the
message names the problem) and a cancelled or failed fit leaves the previous fit of the
material intact.

Storage (format version 1), the engine's input
----------------------------------------------
``material.sgprt.lobe_fit`` (properties.SGPRT_PG_lobe_fit): ``format_version`` (0: none),
``source_file``, ``source_path``, ``source_kind`` ('MERL' / 'SVBRDF_TABLE'),
``lobe_count`` K, ``free_axes``, ``shadowing_components`` C, ``shadowing_samples`` S,
``width`` W, ``height`` H, ``fit_error`` / ``fit_error_max`` (relative RMSE of the
cosine-weighted fitted BRDF against the source over an independent direction grid:
microfacet_fit.relative_rmse, mean / max over texels), ``ndf_error`` (mean relative L2
of the SG fit of D), ``date`` (ISO 8601 UTC), ``seconds``, and ``images``: a collection of
(``role``, ``image``).  A fit is taken by the material's technique when it reads fits (its Blender side's
take_lobe_fit: a bi-scale material's small-scale BRDF, a spherical-harmonics material's tabulated BRDF), else
the technique that renders fits is picked (techniques.rendering_stored("lobe_fit")); clearing the fit sets the
default technique back from that one.

Every image is a FLOAT RGBA image (32-bit float), packed into the .blend (OpenEXR,
float32-exact through save and reopen on 4.2 and 5.0), colour space Non-Color,
alpha_mode CHANNEL_PACKED.  Texel images are W x H; table row 0 (the top, the
numpy image convention) is Blender pixel row H - 1, so the image looks like the table
in the image editor and ``pixels`` reshaped (H, W, 4) and flipped (``[::-1]``) gives
the table's (H, W) order.  Roles (``lobe_fit_images(material)`` returns {role: (H, W, 4)
float32, row 0 at the top}):

    base                 (diffuse kd R, G, B, eta)    rho = kd / pi + specular term (eq. 13)
    lobe_K_axis          (axis x, y, z, sharpness)    K = 0 .. lobe_count-1, sorted by sharpness;
                                                      axis in the local frame (z+ = normal,
                                                      x+ = tangent); (0, 0, 1) unless free_axes
    lobe_K_amplitude     (amplitude R, G, B, 0)       ks times the lobe amplitude (the paper's
                                                      RGB lobe): D_rgb(h) = sum_K amplitude_K
                                                      exp(sharpness_K (h.axis_K - 1))
    shadowing_J          PCA coefficients 4J..4J+3    J = 0 .. ceil(C/4)-1, zero padded
    error                (ndf_error, factorization residual, fit error, 0) per texel
    shadowing_table      S x (C + 2) pixels, value in R (G = B = A = 0): pixel row 0 the
                         polar angles theta_s (radians), row 1 the mean, rows 2.. the C basis
                         vectors (Blender rows, bottom first; no flip)

The shadowing of a texel is S(theta) = max(0, mean + coefficients @ basis) at theta_s,
interpolated linearly, clamped below theta_0 and falling to 0 at pi/2
(svbrdf_table.interpolate_shadowing); eta enters the Fresnel factor F(|i.h|) of eq. 14;
rho(o, i) = kd/pi + F S(o) S(i) D_rgb(h) / (pi (i.n)(o.n)).  ``stored_lobe_fit(material)``
rebuilds a measured.microfacet_fit.LobeFit from the images (what a renderer mirrors).
"""
import datetime
import os
import time

import bpy
import numpy as np
from bpy.props import EnumProperty, IntProperty, StringProperty

from .. import techniques
from ..measured import merl as merl_format
from ..measured import microfacet_fit, svbrdf_table
from . import technique_sides
from .background_job import BackgroundJob, MaterialFileJobOperator, active_material
from .panels import MaterialPanel

FORMAT_VERSION = 1
IMAGE_PREFIX = "SGPRT fit"
MAX_LOBES = 8

# Tests (and scripts) may set this to a callable(fraction, message) -> bool: True cancels the fit.
progress_hook = None


class FitError(ValueError):
    """A source file that cannot be fitted (the message names the file and the problem)."""


# --------------------------------------------------------------------------- the fit job (no bpy)

def read_source(path):
    """('MERL', MerlBrdf) or ('SVBRDF_TABLE', SvbrdfTable); FitError naming the problem."""
    try:
        with open(path, "rb") as stream:
            magic = stream.read(4)
    except OSError as error:
        raise FitError(f"cannot read {os.fspath(path)!r}: {error.strerror or error}") from error
    try:
        if magic[:2] == b"PK":
            return "SVBRDF_TABLE", svbrdf_table.read_svbrdf_table(path)
        return "MERL", merl_format.read_merl(path)
    except (merl_format.MerlFormatError, svbrdf_table.SvbrdfTableError) as error:
        kind = "SVBRDF table" if magic[:2] == b"PK" else "MERL file"
        raise FitError(f"not a valid {kind}: {error}") from error


# A MERL file must hold finite, non-negative samples in at least this fraction of its bins whose directions are
# both above the horizon (real files mark some bins invalid; half or more invalid leaves too little to fit), and
# no sample above MAX_MERL_VALUE per steradian (measured BRDFs stay orders of magnitude below it).
MIN_VALID_FRACTION = 0.75
MAX_MERL_VALUE = 1e6


def _bins_above_horizon():
    (theta_h, theta_d, phi_d), _ = merl_format.bin_centre_angles()
    wo, wi = merl_format.directions_from_half_difference(theta_h, theta_d, phi_d)
    return (wo[..., 2] > 0) & (wi[..., 2] > 0)


def check_merl_samples(source, name):
    """FitError saying what is wrong when the samples of MERL file ``name`` cannot support a fit."""
    above = _bins_above_horizon()
    usable = source.valid & above
    fraction = usable.sum() / max(int(above.sum()), 1)
    counts = ", ".join(f"{count} {kind}" for kind, count in source.counts.items() if count)
    if fraction < MIN_VALID_FRACTION:
        raise FitError(f"{name}: only {int(usable.sum())} of {int(above.sum())} bins above the horizon hold finite, "
                       f"non-negative samples ({fraction:.0%}; {counts or 'none invalid'} channel samples): too few "
                       f"to fit (at least {MIN_VALID_FRACTION:.0%})")
    values = source.rho[usable]
    if values.max() <= 0:
        raise FitError(f"{name}: every valid sample is 0: nothing to fit")
    if values.max() > MAX_MERL_VALUE:
        raise FitError(f"{name}: samples reach {values.max():.3g} per steradian: not a measured BRDF (they stay below "
                       f"{MAX_MERL_VALUE:g})")


class _TexelReference:
    """The source as relative_rmse's reference callable (wo, wi, texels) -> (b, N, 3)."""

    def __init__(self, kind, source):
        self.kind, self.source = kind, source
        self.texel_count = 1 if kind == "MERL" else source.texel_count

    def __call__(self, wo, wi, texels):
        if self.kind == "MERL":
            return np.broadcast_to(self.source.evaluate(wo, wi)[None], (len(texels),) + wo.shape[:-1] + (3,))
        return self.source.evaluate(wo, wi, texels)


def fit_error(kind, source, fit):
    """Per-texel relative RMSE of the fitted BRDF (microfacet_fit.relative_rmse, (i.n)-weighted)
    on an independent coarse grid (offset 0.3): 8k pairs for MERL, 1k per texel for tables."""
    counts = (32, 16, 16, 1) if kind == "MERL" else (16, 8, 8, 1)
    samples = microfacet_fit.half_difference_samples(*counts, offset=0.3)
    return microfacet_fit.relative_rmse(_TexelReference(kind, source), fit.evaluate, samples=samples)


def pack_layers(fit, shape, error):
    """{role: (H, W, 4) float32 (row 0 at the top)} texel layers and the shadowing table (C+2, S, 4)
    (row 0 first) of a LobeFit over ``shape`` (H, W) texels: the storage layout above."""
    height, width = shape
    texels = height * width

    def layer(*channels):
        out = np.zeros((texels, 4), np.float32)
        for index, values in enumerate(channels):
            out[:, index] = np.asarray(values, np.float64).reshape(texels)
        return out.reshape(height, width, 4)

    layers = {"base": layer(*fit.diffuse.T, fit.eta)}
    for k in range(fit.sharpness.shape[1]):
        layers[f"lobe_{k}_axis"] = layer(*fit.axis[:, k].T, fit.sharpness[:, k])
        layers[f"lobe_{k}_amplitude"] = layer(*fit.amplitude[:, k].T)
    coefficients = np.asarray(fit.shadowing_coefficients, np.float64)
    components = coefficients.shape[1]
    for j in range(-(-components // 4)):
        layers[f"shadowing_{j}"] = layer(*coefficients[:, 4 * j:4 * j + 4].T)
    layers["error"] = layer(fit.ndf_error, fit.factorization_residual, error)
    rows = np.concatenate([np.asarray(fit.shadowing_theta, np.float64)[None],
                           np.asarray(fit.shadowing_mean, np.float64)[None],
                           np.asarray(fit.shadowing_basis, np.float64).reshape(components, -1)])
    table = np.zeros(rows.shape + (4,), np.float32)
    table[..., 0] = rows
    return layers, table


class FitJob(BackgroundJob):
    """Reads and fits one file; run() synchronously or start() a thread.  Never touches bpy.

    After run(): ``result`` = dict(kind, shape, fit, layers, shadowing_table, errors, seconds)
    on success; else ``cancelled`` or ``error`` (a message) and result None."""

    verb = "fit"
    thread_name = "sgprt-lobe-fit"

    def __init__(self, path, lobe_count, free_axes=None, shadowing_components=8, verbose=False, hook=None):
        super().__init__(verbose, hook)
        self.path, self.lobe_count, self.free_axes = path, lobe_count, free_axes
        self.shadowing_components = shadowing_components
        self.result = None

    def run(self):
        started = time.perf_counter()
        name = os.path.basename(self.path)
        try:
            if self.record_progress(0.0, f"reading {name}"):
                raise _Cancelled
            kind, source = read_source(self.path)
            if kind == "MERL":
                check_merl_samples(source, name)
            if self.record_progress(0.05, f"read {name}"):
                raise _Cancelled

            def progress(fraction):
                return self.record_progress(0.05 + 0.85 * fraction, f"fitting {self.lobe_count} lobe(s) to {name}")

            if kind == "MERL":
                fit = microfacet_fit.fit_merl(source, self.lobe_count, free_axes=self.free_axes, progress=progress)
                shape = (1, 1)
            else:
                fit = microfacet_fit.fit_lobes(source, self.lobe_count, self.shadowing_components,
                                               free_axes=self.free_axes, progress=progress)
                shape = source.shape
            if fit is None or self.record_progress(0.9, "measuring the fit error"):
                raise _Cancelled
            errors = fit_error(kind, source, fit)
            layers, table = pack_layers(fit, shape, errors)
            if not all(np.all(np.isfinite(a)) for a in list(layers.values()) + [table]):
                raise FitError(f"the fit of {name} produced NaN or Inf values")
            if self.record_progress(1.0, f"fitted {name}"):
                raise _Cancelled
        except _Cancelled:
            self.cancelled = True
            if self.verbose:
                print("[sg-prt] fit cancelled: nothing written", flush=True)
            return
        except np.linalg.LinAlgError as error:      # samples with no microfacet structure: singular systems
            self.error = (f"{name}: the samples do not behave like a microfacet BRDF (the fit's least squares is "
                          f"singular: {error})")
            if self.verbose:
                print(f"[sg-prt] fit failed: {self.error}", flush=True)
            return
        except Exception as error:      # reported by the operator, nothing written
            self.error = str(error) if isinstance(error, FitError) else f"{type(error).__name__}: {error}"
            if self.verbose:
                print(f"[sg-prt] fit failed: {self.error}", flush=True)
            return
        invalid = sum(source.counts.values()) if kind == "MERL" else 0
        self.result = dict(kind=kind, shape=shape, fit=fit, layers=layers, shadowing_table=table, errors=errors,
                           invalid_samples=invalid, seconds=time.perf_counter() - started)


class _Cancelled(Exception):
    pass


# --------------------------------------------------------------------------- storage (main thread)

def new_float_image(name, array):
    """A packed FLOAT RGBA Non-Color image of array (rows, columns, 4), Blender row order as given."""
    rows, columns = array.shape[:2]
    image = bpy.data.images.new(name, width=columns, height=rows, alpha=True, float_buffer=True, is_data=True)
    image.colorspace_settings.is_data = True
    image.alpha_mode = "CHANNEL_PACKED"
    image.pixels.foreach_set(np.ascontiguousarray(array, np.float32).ravel())
    image.update()
    image.pack()
    return image


def float_image_array(image, rows, columns):
    if tuple(image.size) != (columns, rows) or image.channels != 4:
        raise ValueError(f"image '{image.name}' is {tuple(image.size)} x {image.channels}, "
                         f"expected {(columns, rows)} x 4")
    out = np.empty(rows * columns * 4, np.float32)
    image.pixels.foreach_get(out)
    return out.reshape(rows, columns, 4)


def clear_lobe_fit(material):
    """Remove a stored fit (metadata, references, and its images if nothing else uses them)."""
    settings = material.sgprt.lobe_fit
    images = [item.image for item in settings.images if item.image is not None]
    found = settings.format_version != 0 or bool(images)
    settings.images.clear()
    for name in ("format_version", "source_file", "source_path", "source_kind", "lobe_count", "free_axes",
                 "shadowing_components", "shadowing_samples", "width", "height", "fit_error", "fit_error_max",
                 "ndf_error", "date", "seconds"):
        settings.property_unset(name)
    fitted = techniques.rendering_stored("lobe_fit")
    if fitted is not None and techniques.of_settings(material.sgprt) == fitted.name:
        material.sgprt.technique = techniques.DEFAULT
    if "use_fitted_lobes" in material.sgprt.keys():        # the setting of files before techniques
        del material.sgprt["use_fitted_lobes"]
    for image in images:
        if image.users == 0:
            bpy.data.images.remove(image)
    return found


def image_name(material, role):
    return f"{IMAGE_PREFIX} {material.name} {role}"


def store_lobe_fit(material, result, path, free_axes=None):
    """Write a finished FitJob result to a material, replacing any previous fit.  New images are
    made first; on any error they are removed and the previous fit stays."""
    height, width = result["shape"]
    fit = result["fit"]
    made = []
    try:
        for role, array in result["layers"].items():
            made.append((role, new_float_image(image_name(material, role), array[::-1])))
        made.append(("shadowing_table", new_float_image(image_name(material, "shadowing_table"),
                                                   result["shadowing_table"])))
    except Exception:
        for _, image in made:
            bpy.data.images.remove(image)
        raise
    clear_lobe_fit(material)
    settings = material.sgprt.lobe_fit
    for role, image in made:
        image.name = image_name(material, role)      # the previous fit's images are gone: take their names
        item = settings.images.add()
        item.role, item.image = role, image
    errors = np.asarray(result["errors"], np.float64)
    settings.source_file = os.path.basename(path)
    settings.source_path = os.path.abspath(path)
    settings.source_kind = result["kind"]
    settings.lobe_count = int(fit.sharpness.shape[1])
    settings.free_axes = bool(np.any(np.abs(fit.axis[..., :2]) > 0)) if free_axes is None else bool(free_axes)
    settings.shadowing_components = int(fit.shadowing_basis.shape[0])
    settings.shadowing_samples = int(len(fit.shadowing_theta))
    settings.width, settings.height = int(width), int(height)
    settings.fit_error, settings.fit_error_max = float(errors.mean()), float(errors.max())
    settings.ndf_error = float(np.mean(fit.ndf_error))
    settings.date = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
    settings.seconds = float(result["seconds"])
    settings.format_version = FORMAT_VERSION
    technique_sides.take_lobe_fit(material)
    material.update_tag()


def fit_status(material):
    """(state, message): state 'NONE', 'VALID' or 'INVALID' (missing or wrong-size images)."""
    settings = material.sgprt.lobe_fit
    if settings.format_version == 0:
        return "NONE", "no fitted lobes"
    if settings.format_version != FORMAT_VERSION:
        return "INVALID", f"fit format {settings.format_version}, this add-on reads {FORMAT_VERSION}: re-fit"
    roles = {item.role: item.image for item in settings.images}
    expected = expected_roles(settings.lobe_count, settings.shadowing_components)
    missing = [role for role in expected if roles.get(role) is None]
    if missing:
        return "INVALID", f"fit images missing ({', '.join(missing)}): re-fit"
    for role in expected:
        size = ((settings.shadowing_samples, settings.shadowing_components + 2) if role == "shadowing_table"
                else (settings.width, settings.height))
        if tuple(roles[role].size) != size:
            return "INVALID", f"fit image '{roles[role].name}' has the wrong size: re-fit"
        if not roles[role].is_float:
            return "INVALID", f"fit image '{roles[role].name}' is not a float image: re-fit"
    return "VALID", (f"{settings.lobe_count} lobe(s), {settings.width}x{settings.height} texel(s), "
                     f"error {settings.fit_error:.3f}")


def expected_roles(lobe_count, shadowing_components):
    roles = ["base"]
    for k in range(lobe_count):
        roles += [f"lobe_{k}_axis", f"lobe_{k}_amplitude"]
    roles += [f"shadowing_{j}" for j in range(-(-shadowing_components // 4))]
    return roles + ["error", "shadowing_table"]


def lobe_fit_images(material):
    """{role: float32 array} of a valid stored fit: texel layers (H, W, 4) row 0 at the top, and
    'shadowing_table' (C + 2, S, 4) row 0 first; ValueError if the fit is missing or damaged."""
    state, message = fit_status(material)
    if state != "VALID":
        raise ValueError(f"material '{material.name}': {message}")
    settings = material.sgprt.lobe_fit
    out = {}
    for item in settings.images:
        if item.role == "shadowing_table":
            out[item.role] = float_image_array(item.image, settings.shadowing_components + 2, settings.shadowing_samples)
        else:
            out[item.role] = float_image_array(item.image, settings.height, settings.width)[::-1]
    return out


def stored_lobe_fit(material):
    """A measured.microfacet_fit.LobeFit (B = H W texels, float64) rebuilt from the stored images."""
    settings = material.sgprt.lobe_fit
    arrays = lobe_fit_images(material)
    flat = {role: a.reshape(-1, 4).astype(np.float64) for role, a in arrays.items() if role != "shadowing_table"}
    lobes = range(settings.lobe_count)
    components = settings.shadowing_components
    coefficients = np.concatenate([flat[f"shadowing_{j}"] for j in range(-(-components // 4))] or
                                  [np.zeros((len(flat["base"]), 0))], axis=1)[:, :components]
    table = arrays["shadowing_table"][..., 0].astype(np.float64)
    return microfacet_fit.LobeFit(
        diffuse=flat["base"][:, :3], eta=flat["base"][:, 3],
        axis=np.stack([flat[f"lobe_{k}_axis"][:, :3] for k in lobes], axis=1),
        sharpness=np.stack([flat[f"lobe_{k}_axis"][:, 3] for k in lobes], axis=1),
        amplitude=np.stack([flat[f"lobe_{k}_amplitude"][:, :3] for k in lobes], axis=1),
        shadowing_theta=table[0], shadowing_mean=table[1], shadowing_basis=table[2:],
        shadowing_coefficients=coefficients, ndf_error=flat["error"][:, 0],
        factorization_residual=flat["error"][:, 1])


# --------------------------------------------------------------------------- operators and panel

AXES = (("AUTO", "Auto", "Lobes around the normal for 1-2 lobes and isotropic data, else free axes"),
        ("FREE", "Free", "Every lobe's axis fitted freely"))


class SGPRT_OT_fit_lobes(MaterialFileJobOperator, bpy.types.Operator):
    """Fit SG lobes to a measured BRDF (MERL .binary) or an SVBRDF table (.npz) and store them in the active material"""
    bl_idname = "sgprt.fit_lobes"
    bl_label = "Fit Lobes"
    bl_options = {"REGISTER", "UNDO"}

    # SKIP_SAVE: the panel's button must open the file browser, not silently re-fit the last file
    filepath: StringProperty(name="File", subtype="FILE_PATH", options={"SKIP_SAVE"},
                             description="MERL .binary or SVBRDF table .npz")
    filter_glob: StringProperty(default="*.binary;*.npz", options={"HIDDEN"})
    lobe_count: IntProperty(name="Lobes", default=2, min=1, max=MAX_LOBES, description="SG lobes per texel")
    axes: EnumProperty(name="Axes", items=AXES, default="AUTO", description="Where the lobe axes may point")
    shadowing_components: IntProperty(name="Shadowing Components", default=8, min=1, max=16,
                                      description="PCA components of the shadowing S(theta) (tables)")

    job_label = "SG-PRT fit"
    stored_as, result_label, previous = "a fit", "SG-PRT fit", "fit"
    _running = False        # one fit at a time

    @classmethod
    def poll(cls, context):
        return not SGPRT_OT_fit_lobes._running and active_material(context) is not None

    def _make_job(self, path):
        free_axes = True if self.axes == "FREE" else None
        return FitJob(path, self.lobe_count, free_axes, self.shadowing_components, hook=progress_hook)

    def _store(self, material, job):
        store_lobe_fit(material, job.result, job.path, job.free_axes)

    def _done_message(self, material, job):
        settings = material.sgprt.lobe_fit
        return (f"SG-PRT fitted {settings.lobe_count} lobe(s) to {settings.source_file} on "
                f"'{material.name}' ({settings.width}x{settings.height}, error "
                f"{settings.fit_error:.3f}, {settings.seconds:.1f} s)"
                + (f"; {job.result['invalid_samples']} negative/NaN/Inf samples ignored"
                   if job.result["invalid_samples"] else ""))


class SGPRT_OT_clear_lobe_fit(bpy.types.Operator):
    """Remove the stored lobe fit of the active material (and its images)"""
    bl_idname = "sgprt.clear_lobe_fit"
    bl_label = "Clear Lobe Fit"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return active_material(context) is not None and not SGPRT_OT_fit_lobes._running

    def execute(self, context):
        material = active_material(context)
        if not clear_lobe_fit(material):
            self.report({"INFO"}, f"SG-PRT: '{material.name}' has no lobe fit")
            return {"CANCELLED"}
        material.update_tag()
        self.report({"INFO"}, f"SG-PRT cleared the lobe fit of '{material.name}'")
        return {"FINISHED"}


class SGPRT_PT_material_lobe_fit(MaterialPanel, bpy.types.Panel):
    bl_label = "Measured BRDF (Lobe Fit)"
    bl_parent_id = "SGPRT_PT_material"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.layout
        material = context.material
        settings = material.sgprt.lobe_fit
        row = layout.row(align=True)
        row.operator(SGPRT_OT_fit_lobes.bl_idname, icon="FILE_FOLDER")
        row.operator(SGPRT_OT_clear_lobe_fit.bl_idname, text="", icon="X")
        try:
            state, message = fit_status(material)
        except Exception as error:      # a panel must draw whatever the data
            state, message = "INVALID", f"cannot read the fit ({error})"
        column = layout.column(align=True)
        if state == "NONE":
            column.label(text="No fitted lobes: renders the model above", icon="INFO")
            return
        use = technique_sides.lobe_fit_use(material)
        if use is None:
            column.label(text="Renders the model: pick the fitted technique above to render the fit", icon="INFO")
        elif use:
            column.label(text=use, icon="INFO")
        if state == "INVALID":
            column.alert = True
            column.label(text=message, icon="ERROR")
            return
        kind = "MERL" if settings.source_kind == "MERL" else "SVBRDF table"
        column.label(text=f"{settings.source_file} ({kind})", icon="CHECKMARK")
        column.label(text=f"{settings.lobe_count} lobe(s){' (free axes)' if settings.free_axes else ''}, "
                          f"{settings.width}x{settings.height} texel(s)")
        column.label(text=f"Error {settings.fit_error:.3f} (max {settings.fit_error_max:.3f}), "
                          f"NDF {settings.ndf_error:.3f}")
        column.label(text=f"Fitted {settings.date} in {settings.seconds:.1f} s")


classes = (SGPRT_OT_fit_lobes, SGPRT_OT_clear_lobe_fit, SGPRT_PT_material_lobe_fit)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
