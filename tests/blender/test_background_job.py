"""Long operators' progress text (blender/background_job.py): the percentage, the step, and the time left
estimated from the pace so far."""
from sg_prt_addon.blender import background_job


def test_time_left_follows_the_pace(monkeypatch):
    clock = [100.0]
    monkeypatch.setattr(background_job.time, "monotonic", lambda: clock[0])
    job = background_job.BackgroundJob()
    assert job.seconds_left() is None and job.progress_text() == "0%: starting"
    job.record_progress(0.0, "Floor: visibility 0/4225 vertices")
    clock[0] += 10.0
    job.record_progress(0.25, "Floor: visibility 1056/4225 vertices")
    assert job.seconds_left() == 30.0                  # a quarter in 10 s: three quarters in 30 s more
    assert job.progress_text() == "25%: Floor: visibility 1056/4225 vertices, about 30 s left"
    job.record_progress(0.01, "early")                 # too little done to say
    assert job.seconds_left() is None


def test_time_text():
    assert [background_job.time_text(s) for s in (0.4, 8, 59.6, 130, 720, 3900)] == \
        ["0 s", "8 s", "1 min 0 s", "2 min 10 s", "12 min", "1 h 5 min"]


class _Solve(background_job.BackgroundJob):
    """A job in one long step that cannot look at Esc until it ends (a solver's single call)."""

    def __init__(self, seconds):
        super().__init__()
        self.seconds = seconds
        self.result = None

    def run(self):
        import time
        time.sleep(self.seconds)
        self.result = "made"


class _Operator(background_job.ModalJobOperator):
    """The mixin's Esc and timer path, with the reports kept (an operator's report() outside a window)."""

    def __init__(self, job):
        self._job, self._timer, self.reports = job, None, []

    def report(self, kinds, message):
        self.reports.append((set(kinds), message))

    def _finish(self, context, job):
        return {"FINISHED"}


class _Event:
    def __init__(self, kind, value="NOTHING"):
        self.type, self.value = kind, value


def test_esc_ends_the_operator_within_a_second_whatever_the_job_does(addon):
    """Esc during a step the job cannot interrupt: the operator ends within CANCEL_GRACE plus a timer tick,
    reports that nothing was written, and the thread finishing later changes nothing it reads."""
    import time

    import bpy

    job = _Solve(3.0)
    operator = _Operator(job)
    job.start()
    pressed = time.monotonic()
    assert operator.modal(bpy.context, _Event("ESC", "PRESS")) == {"RUNNING_MODAL"}
    outcome = {"PASS_THROUGH"}
    while outcome == {"PASS_THROUGH"} and time.monotonic() - pressed < 2.5:
        time.sleep(0.25)                        # the operator's timer interval
        outcome = operator.modal(bpy.context, _Event("TIMER"))
    assert outcome == {"CANCELLED"} and time.monotonic() - pressed < 1.0
    assert job.running and job.result is None
    assert any("cancelled: nothing written" in message for _, message in operator.reports)
    assert not type(operator)._running
    job.join()
