"""Long operators (bake, fit) that run synchronously under `blender -b` and in a thread,
with a progress bar and Esc, in the UI.

BackgroundJob: the work, in a thread that never touches bpy; progress and cancellation
are shared through a lock and an event.  ModalJobOperator: the operator side of the UI
path (timer, progress bar, status text, Esc, clean-up on every exit); FileJobOperator: an operator on a
file (the lobe fit, the BRDF factorization).
"""
import os
import threading
import time

import bpy


class BackgroundJob:
    """Subclasses implement run() (call it directly for the synchronous path) and report
    progress through record_progress(), which answers whether to stop."""

    verb = "job"            # in the printed progress lines: "[sg-prt] <verb> 40% ..."
    thread_name = "sgprt-job"

    def __init__(self, verbose=False, hook=None):
        self.verbose = verbose
        self.hook = hook                # hook(fraction, message) -> True cancels (tests)
        self.cancelled = False
        self.error = None
        self.fraction = 0.0
        self.message = "starting"
        self._cancel = threading.Event()
        self._lock = threading.Lock()
        self._printed_decile = -1
        self._thread = None
        self._started = None            # time.monotonic() of the first progress, for seconds_left

    def cancel(self):
        self._cancel.set()

    @property
    def cancelling(self):
        return self._cancel.is_set()

    @property
    def running(self):
        return self._thread is not None and self._thread.is_alive()

    def start(self):
        self._thread = threading.Thread(target=self.run, name=self.thread_name, daemon=True)
        self._thread.start()

    def join(self, timeout=None):
        if self._thread is not None:
            self._thread.join(timeout)

    def record_progress(self, fraction, message, always_print=False):
        """Share progress; print it by deciles when verbose; True when the job must stop."""
        fraction = min(max(float(fraction), 0.0), 1.0)
        with self._lock:
            self.fraction, self.message = fraction, message
            if self._started is None:
                self._started = time.monotonic()
        decile = int(fraction * 10)
        if self.verbose and (decile > self._printed_decile or always_print):
            self._printed_decile = decile
            print(f"[sg-prt] {self.verb} {fraction * 100:3.0f}% {message}", flush=True)
        if self.hook is not None and self.hook(fraction, message):
            self._cancel.set()
        return self._cancel.is_set()

    def seconds_left(self):
        """An estimate of the time left from the pace so far, once there is one (2% done and 2 s gone), else
        None."""
        if self._started is None:
            return None
        elapsed = time.monotonic() - self._started
        if self.fraction < 0.02 or elapsed < 2.0:
            return None
        return elapsed * (1.0 - self.fraction) / self.fraction

    def progress_text(self):
        """'40%: <message>, about 12 s left' for status bars."""
        left = self.seconds_left()
        estimate = "" if left is None else f", about {time_text(left)} left"
        return f"{self.fraction * 100:.0f}%: {self.message}{estimate}"

    def run(self):
        raise NotImplementedError


def time_text(seconds):
    """A duration as people read it: '8 s', '2 min 10 s', '1 h 5 min'."""
    seconds = int(round(seconds))
    if seconds < 60:
        return f"{seconds} s"
    if seconds < 3600:
        return f"{seconds // 60} min {seconds % 60} s" if seconds < 600 else f"{round(seconds / 60)} min"
    return f"{seconds // 3600} h {(seconds % 3600) // 60} min"


class ModalJobOperator:
    """Mixin for a bpy.types.Operator whose invoke() starts a BackgroundJob: call
    start_modal(context, job); implement _finish(context, job) -> the operator's result.
    The class attribute `_running` is shared by all instances: one job of a kind at a time.

    Esc cancels: a job that has not stopped CANCEL_GRACE seconds later (a solve it cannot interrupt) is left
    to end in its thread, its result never read, and the operator ends at once with nothing written."""

    job_label = "SG-PRT job"
    _running = False
    CANCEL_GRACE = 0.5

    def start_modal(self, context, job, interval=0.25):
        self._job = job
        type(self)._running = True
        job.start()
        window_manager = context.window_manager
        self._timer = window_manager.event_timer_add(interval, window=context.window)
        window_manager.progress_begin(0, 100)
        window_manager.modal_handler_add(self)
        self._status(context, f"{self.job_label}: starting (Esc cancels)")
        return {"RUNNING_MODAL"}

    def run_now(self, context, job):
        """The job in this thread, printing its progress ("[sg-prt] bake 40% ..."), then _finish."""
        job.verbose = True
        job.run()
        return self._finish(context, job)

    def _status(self, context, text):
        if context.workspace is not None:
            context.workspace.status_text_set(text)

    def _cleanup(self, context):
        type(self)._running = False
        window_manager = context.window_manager
        if getattr(self, "_timer", None) is not None:
            window_manager.event_timer_remove(self._timer)
            self._timer = None
        window_manager.progress_end()
        self._status(context, None)

    def modal(self, context, event):
        job = self._job
        try:
            if event.type == "ESC" and event.value == "PRESS":
                job.cancel()
                self._cancelled_at = time.monotonic()
                self._status(context, f"{self.job_label}: cancelling...")
                return {"RUNNING_MODAL"}
            if event.type == "TIMER":
                context.window_manager.progress_update(int(job.fraction * 100))
                if not job.cancelling:
                    self._status(context, f"{self.job_label} {job.progress_text()} (Esc cancels)")
                if not job.running:
                    job.join()
                    self._cleanup(context)
                    return self._finish(context, job)
                if job.cancelling and time.monotonic() - getattr(self, "_cancelled_at", 0.0) >= self.CANCEL_GRACE:
                    self._cleanup(context)      # the thread ends on its own; nothing reads what it made
                    self.report({"WARNING"}, f"{self.job_label} cancelled: nothing written, the previous result kept")
                    return {"CANCELLED"}
            return {"PASS_THROUGH"}
        except Exception as error:      # never leave the thread running or the button disabled
            job.cancel()
            job.join()
            self._cleanup(context)
            self.report({"ERROR"}, f"{self.job_label} failed, nothing written: {error}")
            return {"CANCELLED"}

    def cancel(self, context):
        job = getattr(self, "_job", None)
        if job is not None:
            job.cancel()
            job.join()
        self._cleanup(context)


class SceneJobOperator(ModalJobOperator):
    """ModalJobOperator for a job on the scene (a bake): _prepare(context) -> the job or None after reporting
    why not; execute runs it synchronously with printed progress (blender -b, scripts, tests), invoke in a
    thread with the window manager's progress and Esc."""

    def execute(self, context):
        job = self._prepare(context)
        return {"CANCELLED"} if job is None else self.run_now(context, job)

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        job = self._prepare(context)
        if job is None:
            return {"CANCELLED"}
        return self.start_modal(context, job)


class FileJobOperator(ModalJobOperator):
    """ModalJobOperator for a job on a file: `filepath` (the file browser opens without one), _prepare(context)
    -> (target, job) or None after reporting why not; execute runs the job synchronously (blender -b,
    scripts), invoke in a thread with progress and Esc."""

    def execute(self, context):
        if getattr(self, "_from_browser", False) and not bpy.app.background and context.window is not None:
            # the file browser confirms through execute(); Blender keeps an operator whose execute
            # returns RUNNING_MODAL (it frees it only on FINISHED / CANCELLED): go on as a modal job
            self._from_browser = False
            return self._start_modal(context)
        prepared = self._prepare(context)
        if prepared is None:
            return {"CANCELLED"}
        return self.run_now(context, prepared[1])

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        if not self.filepath:
            self._from_browser = True
            context.window_manager.fileselect_add(self)
            return {"RUNNING_MODAL"}
        return self._start_modal(context)

    def _start_modal(self, context):
        prepared = self._prepare(context)
        if prepared is None:
            return {"CANCELLED"}
        return self.start_modal(context, prepared[1], interval=0.2)


def active_material(context):
    """The material an operator on 'the active material' acts on: the context's, else the active object's."""
    material = getattr(context, "material", None)
    if material is None and context.active_object is not None:
        material = context.active_object.active_material
    return material


class MaterialFileJobOperator(FileJobOperator):
    """A FileJobOperator that stores what its job makes from a file in the active material (Fit Lobes, Factor
    BRDF): the checks before the job and the outcomes after it, worded from `job_label` ("SG-PRT fit"),
    `stored_as` ("a fit": what a linked material cannot store), `result_label` ("SG-PRT fit": what could
    not be stored) and `previous` ("fit": what is kept).  Subclasses give _make_job(path) and, on success,
    _store(material, job) and _done_message(material, job)."""

    stored_as = "a result"
    result_label = "SG-PRT result"
    previous = "result"
    previous_verb = "is"

    def _prepare(self, context):
        """(material, job) or None after reporting why not."""
        material = active_material(context)
        if material is None:
            self.report({"ERROR"}, f"{self.job_label}: no active material")
            return None
        if material.library is not None:
            self.report({"ERROR"}, f"{self.job_label}: material '{material.name}' is linked and cannot store "
                                   f"{self.stored_as}")
            return None
        if not self.filepath:
            self.report({"ERROR"}, f"{self.job_label}: no file given")
            return None
        path = bpy.path.abspath(self.filepath)
        if not os.path.isfile(path):
            self.report({"ERROR"}, f"{self.job_label}: file not found: {path}")
            return None
        self._material_name = material.name
        return material, self._make_job(path)

    def _finish(self, context, job):
        if job.cancelled:
            self.report({"WARNING"}, f"{self.job_label} cancelled: nothing written, the previous {self.previous} "
                                     f"{self.previous_verb} kept")
            return {"CANCELLED"}
        if job.error is not None:
            self.report({"ERROR"}, f"{self.job_label} failed, nothing written: {job.error}")
            return {"CANCELLED"}
        material = bpy.data.materials.get(self._material_name)
        if material is None:
            self.report({"ERROR"}, f"{self.job_label}: material '{self._material_name}' was removed: nothing written")
            return {"CANCELLED"}
        try:
            self._store(material, job)
        except Exception as error:
            self.report({"ERROR"}, f"{self.result_label} could not be stored, previous {self.previous} kept: {error}")
            return {"CANCELLED"}
        self.report({"INFO"}, self._done_message(material, job))
        return {"FINISHED"}
