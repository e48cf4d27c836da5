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
