"""Factor BRDF operator: a measured BRDF (a MERL .binary, or one texel of an SVBRDF table .npz) factorized into
p(o) q(h) p(i) r(o.h) maps (measured/homomorphic.py, mccool2001) and stored in the active material for the
factored technique.  The factors are one BRDF for the whole surface: a table's spatial variation is Fit Lobes'.

Storage, per material (format 1): ``material.sgprt.factorization`` (SGPRT_PG_factorization below):
``format_version``, ``source_file``, ``source_path``, ``source_texel`` (-1: a MERL file), ``form``,
``resolution``, ``alpha_scale`` (alpha A, RGB), ``lobe_sharpness`` (the glossy environment lookup's), ``samples`` (valid BRDF samples fitted), ``masked`` (the
NaN, Inf and negative channel samples left out), ``error`` (relative RMS against the source, cosine weighted),
``date``, ``seconds``, and ``images``: (``role``, ``image``) for p, q, r (the log-factor maps, RGB) and
albedo, packed FLOAT RGBA images whose pixels round-trip bit-exactly through save and reopen.
A factorization sets the material's technique to FACTORED; clearing it sets the default back.
Results are written only when the job finished: a failed or cancelled one leaves the previous factors.
"""
import datetime
import os
import time

import bpy
import numpy as np
from bpy.props import CollectionProperty, EnumProperty, FloatProperty, FloatVectorProperty, IntProperty, StringProperty

from .... import techniques
from ....blender import lobe_fit
from ....blender.background_job import BackgroundJob, MaterialFileJobOperator, active_material
from ....blender.panels import MaterialPanel
from ....blender.properties import SGPRT_PG_lobe_fit_image
from ....measured import homomorphic
from .. import factored

FORMAT_VERSION = 1
IMAGE_PREFIX = "SGPRT factors"
ROLES = ("p", "q", "r", "albedo")
FORMS = tuple((form, homomorphic.FORM_LABELS[form], f"mccool2001 factors {homomorphic.FORM_LABELS[form]}")
              for form in ("pqpr", "pqp", "pq"))
SAMPLES = 256          # views x lights of the fit

# Tests (and scripts) may set this to a callable(fraction, message) -> bool: True cancels the job.
progress_hook = None


class SGPRT_PG_factorization(bpy.types.PropertyGroup):
    """A measured BRDF factorized by sgprt.factor_brdf (layout: factorization.py)."""
    format_version: IntProperty(name="Format Version", default=0, description="0: no factors stored")
    source_file: StringProperty(name="Source File", description="File name the factors were made from")
    source_path: StringProperty(name="Source Path", description="Full path the factors were made from")
    source_texel: IntProperty(name="Source Texel", default=-1, min=-1,
                              description="The SVBRDF table texel factorized (row-major); -1: a MERL file")
    form: StringProperty(name="Form", description="measured.homomorphic.FORMS key")
    resolution: IntProperty(name="Resolution", default=0, min=0)
    alpha_scale: FloatVectorProperty(name="Scale", size=3, default=(1.0, 1.0, 1.0),
                                     description="alpha A of the factored BRDF (RGB)")
    lobe_sharpness: FloatProperty(name="Lobe Sharpness", default=1.0, description="Of the glossy environment lookup")
    samples: IntProperty(name="Samples", default=0, min=0)
    masked: IntProperty(name="Masked Samples", default=0, min=0, description="NaN, Inf and negative samples left out")
    error: FloatProperty(name="Error", default=0.0, description="Relative RMS against the source, cosine weighted")
    date: StringProperty(name="Date", description="When the factors were stored (ISO 8601 UTC)")
    seconds: FloatProperty(name="Seconds", default=0.0)
    images: CollectionProperty(type=SGPRT_PG_lobe_fit_image, name="Images")
    previous_technique: StringProperty(name="Technique Before",
                                       description="The material's technique before the factors set theirs: "
                                                   "Clear BRDF Factors gives it back")



class FactorError(ValueError):
    """Why a source cannot be factorized (the operator reports it; nothing is written)."""


class FactorJob(BackgroundJob):
    """Reads and factorizes one file; run() synchronously or start() a thread.  Never touches bpy."""

    verb = "factorization"
    thread_name = "sgprt-factor-brdf"

    def __init__(self, path, form, resolution, texel=0, verbose=False, hook=None):
        super().__init__(verbose, hook)
        self.path, self.form, self.resolution, self.texel = path, form, int(resolution), int(texel)
        self.source_texel = -1
        self.result = None

    def run(self):
        started = time.perf_counter()
        name = os.path.basename(self.path)
        try:
            if self.record_progress(0.0, f"reading {name}"):
                return self._cancelled()
            kind, source = lobe_fit.read_source(self.path)
            self.source_texel = -1 if kind == "MERL" else self.texel
            wo, wi, values = self._samples(kind, source, name)
            if self.record_progress(0.2, f"factorizing {name}"):
                return self._cancelled()
            factorization = homomorphic.factorize(wo, wi, values, form=self.form, resolution=self.resolution)
            if self.record_progress(0.8, "tabulating the albedo"):
                return self._cancelled()
            tables = factored.tables_of(factorization)
            ok = np.all(np.isfinite(values), axis=1)
            approximation = factorization.evaluate(wo[ok], wi[ok])
            weight = wi[ok, 2:3]
            error = float(np.sqrt(np.sum(((approximation - values[ok]) * weight) ** 2)
                                  / max(np.sum((values[ok] * weight) ** 2), 1e-300)))
            arrays = dict(tables.maps, albedo=tables.albedo)
            if not all(np.all(np.isfinite(array)) for array in arrays.values()):
                raise FactorError(f"the factorization of {name} produced NaN or Inf values")
            if self.record_progress(1.0, f"factorized {name}"):
                return self._cancelled()
        except (FactorError, lobe_fit.FitError) as error:
            self.error = str(error)
        except Exception as error:      # reported by the operator, nothing written
            self.error = f"{type(error).__name__}: {error}"
        else:
            self.result = dict(tables=tables, arrays=arrays, error=error, masked=sum(factorization.counts.values()),
                               samples=factorization.sample_count, seconds=time.perf_counter() - started)
        if self.error and self.verbose:
            print(f"[sg-prt] factorization failed: {self.error}", flush=True)

    def _samples(self, kind, source, name):
        if kind == "MERL":
            lobe_fit.check_merl_samples(source, name)
            return homomorphic.sample_merl(source, SAMPLES)
        height, width = source.shape
        if not 0 <= self.texel < source.texel_count:
            raise FactorError(f"{name}: texel {self.texel} is outside the table's {height} x {width} = "
                              f"{source.texel_count} texels (row-major, 0 to {source.texel_count - 1})")
        return homomorphic.sample_table_texel(source, self.texel, SAMPLES)

    def _cancelled(self):
        self.cancelled = True
        if self.verbose:
            print("[sg-prt] factorization cancelled: nothing written", flush=True)


# --------------------------------------------------------------------------- storage (main thread)

def image_name(material, role):
    return f"{IMAGE_PREFIX} {material.name} {role}"


def clear_factorization(material):
    """Remove stored factors (metadata, references, and their images if nothing else uses them); a material on
    the factored technique gets back the technique it had before the factors were stored (the default if that
    is unknown)."""
    settings = material.sgprt.factorization
    images = [item.image for item in settings.images if item.image is not None]
    found = settings.format_version != 0 or bool(images)
    settings.images.clear()
    previous = settings.previous_technique
    for name in ("format_version", "source_file", "source_path", "source_texel", "form", "resolution", "alpha_scale",
                 "lobe_sharpness", "samples", "masked", "error", "date", "seconds", "previous_technique"):
        settings.property_unset(name)
    if techniques.of_settings(material.sgprt) == factored.NAME:
        usable = previous in techniques.names() and previous != factored.NAME
        material.sgprt.technique = previous if usable else techniques.DEFAULT
    for image in images:
        if image.users == 0:
            bpy.data.images.remove(image)
    return found


def store_factorization(material, result, path, form, texel=-1):
    """Write a finished job's factors to a material, replacing any previous ones."""
    made = [(role, lobe_fit.new_float_image(image_name(material, role), result["arrays"][role]))
            for role in ROLES if role in result["arrays"]]
    settings = material.sgprt.factorization
    current = techniques.of_settings(material.sgprt)
    previous = settings.previous_technique if current == factored.NAME else current
    clear_factorization(material)
    settings.previous_technique = previous
    for role, image in made:
        image.name = image_name(material, role)
        item = settings.images.add()
        item.role, item.image = role, image
    tables = result["tables"]
    settings.source_file, settings.source_path = os.path.basename(path), os.path.abspath(path)
    settings.source_texel = int(texel)
    settings.form, settings.resolution = form, int(tables.factorization.resolution)
    settings.alpha_scale = tuple(float(x) for x in tables.scale)
    settings.lobe_sharpness = float(tables.lobe_sharpness)
    settings.samples, settings.masked = int(result["samples"]), int(result["masked"])
    settings.error, settings.seconds = float(result["error"]), float(result["seconds"])
    settings.date = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
    settings.format_version = FORMAT_VERSION
    material.sgprt.technique = factored.NAME
    material.update_tag()


def factorization_status(material):
    """('NONE' | 'VALID' | 'INVALID', message) of a material's stored factors."""
    settings = material.sgprt.factorization
    if settings.format_version == 0 and not len(settings.images):
        return "NONE", ""
    if settings.format_version != FORMAT_VERSION:
        return "INVALID", f"factors format {settings.format_version}, this add-on reads {FORMAT_VERSION}: factor again"
    roles = {item.role: item.image for item in settings.images}
    wanted = [role for role in ROLES if role != "r" or "r" in homomorphic.FORMS.get(settings.form, ())]
    missing = [role for role in wanted if roles.get(role) is None]
    if missing or settings.form not in homomorphic.FORMS:
        return "INVALID", f"stored factors damaged (missing {', '.join(missing) or 'form'}): factor again"
    return "VALID", (f"{source_label(settings)}: {homomorphic.FORM_LABELS[settings.form]}, {settings.resolution}^2, "
                     f"error {settings.error:.3f}")


def source_label(settings):
    """The stored factors' source: the file name, and the texel of a table."""
    texel = f" texel {settings.source_texel}" if settings.source_texel >= 0 else ""
    return settings.source_file + texel


def stored_tables(material):
    """factored.FactoredTables of a material's VALID stored factors, else None (factorization_status says why)."""
    if factorization_status(material)[0] != "VALID":
        return None
    settings = material.sgprt.factorization
    roles = {item.role: item.image for item in settings.images}
    size = int(settings.resolution)
    shapes = {"p": (size, size), "q": (size, size), "r": (1, size), "albedo": (size, size)}
    try:
        arrays = {role: lobe_fit.float_image_array(roles[role], *shapes[role]) for role in roles if role in shapes}
    except ValueError:
        return None
    channels = 3
    log_factors = {role: arrays[role][..., :channels] for role in ("p", "q", "r") if role in arrays}
    factorization = homomorphic.Factorization(settings.form, size, log_factors, np.ones(channels), np.ones(channels))
    signature = (settings.date, settings.source_path, settings.seconds, settings.form, size,
                 tuple(item.image.name for item in settings.images if item.image is not None))
    return factored.FactoredTables(factorization, {role: arrays[role] for role in log_factors}, arrays["albedo"],
                                   np.asarray(settings.alpha_scale, np.float32), float(settings.lobe_sharpness),
                                   signature)


# --------------------------------------------------------------------------- operators and panel

class SGPRT_OT_factor_brdf(MaterialFileJobOperator, bpy.types.Operator):
    """Factorize a measured BRDF (MERL .binary, or one texel of an SVBRDF table .npz) into p(o) q(h) p(i) r(o.h) maps (McCool 2001) and store them in the active material"""
    bl_idname = "sgprt.factor_brdf"
    bl_label = "Factor BRDF"
    bl_options = {"REGISTER", "UNDO"}

    filepath: StringProperty(name="File", subtype="FILE_PATH", options={"SKIP_SAVE"},
                             description="MERL .binary or SVBRDF table .npz")
    filter_glob: StringProperty(default="*.binary;*.npz", options={"HIDDEN"})
    form: EnumProperty(name="Factors", items=FORMS, default="pqpr", description="The factored form")
    resolution: IntProperty(name="Resolution", default=64, min=8, max=128, description="Texels a side of each map")
    texel: IntProperty(name="Texel", default=0, min=0,
                       description="For an SVBRDF table: the texel (row-major index) whose BRDF is factorized, as one "
                                   "BRDF for the whole surface")

    job_label = "SG-PRT factorization"
    stored_as, result_label, previous, previous_verb = "factors", "SG-PRT factors", "factors", "are"
    _running = False

    @classmethod
    def poll(cls, context):
        return not SGPRT_OT_factor_brdf._running and active_material(context) is not None

    def _make_job(self, path):
        return FactorJob(path, self.form, self.resolution, self.texel, hook=progress_hook)

    def _store(self, material, job):
        store_factorization(material, job.result, job.path, job.form, job.source_texel)

    def _done_message(self, material, job):
        settings = material.sgprt.factorization
        return (f"SG-PRT factorized {source_label(settings)} on '{material.name}' "
                f"({homomorphic.FORM_LABELS[settings.form]}, {settings.resolution}^2, error {settings.error:.3f}, "
                f"{settings.seconds:.1f} s"
                + (f", {settings.masked} NaN/Inf/negative samples left out)" if settings.masked else ")"))


class SGPRT_OT_clear_factorization(bpy.types.Operator):
    """Remove the stored BRDF factors of the active material (and their images)"""
    bl_idname = "sgprt.clear_factorization"
    bl_label = "Clear BRDF Factors"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return active_material(context) is not None and not SGPRT_OT_factor_brdf._running

    def execute(self, context):
        material = active_material(context)
        before = techniques.of_settings(material.sgprt)
        if not clear_factorization(material):
            self.report({"INFO"}, "SG-PRT: no stored factors")
        after = techniques.of_settings(material.sgprt)
        if after != before:
            self.report({"INFO"}, f"SG-PRT: '{material.name}' renders with {techniques.get(after).label} again")
        return {"FINISHED"}


class SGPRT_PT_material_factorization(MaterialPanel, bpy.types.Panel):
    bl_label = "BRDF Factors"
    bl_parent_id = "SGPRT_PT_material"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.layout
        material = context.material
        row = layout.row(align=True)
        row.operator(SGPRT_OT_factor_brdf.bl_idname, icon="FILE_FOLDER")
        row.operator(SGPRT_OT_clear_factorization.bl_idname, text="", icon="X")
        state, message = factorization_status(material)
        column = layout.column(align=True)
        if state == "NONE":
            column.label(text="No stored factors: the factored technique factorizes the model", icon="INFO")
            return
        column.alert = state == "INVALID"
        column.label(text=message, icon="ERROR" if state == "INVALID" else "CHECKMARK")


classes = (SGPRT_OT_factor_brdf, SGPRT_OT_clear_factorization, SGPRT_PT_material_factorization)

