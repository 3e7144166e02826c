"""The whole identification run (``railadhesion identify``): stages and outputs."""

import minisim
import pandas as pd

from railadhesion.identification import brake_tests, pipeline
from railadhesion.identification.logs import braking_log_from_frame


def test_each_progress_label_fires_when_its_stage_starts(mini_run, mini_vehicle, monkeypatch,
                                                         tmp_path):
    # the progress bar names the stage that is running: every label comes before the work it
    # names, and after the work of the stage before it
    events = []

    def spy(module, name):
        real = getattr(module, name)

        def wrapped(*args, **kwargs):
            events.append(name)
            return real(*args, **kwargs)

        monkeypatch.setattr(module, name, wrapped)

    spy(brake_tests, "_axle_adhesion")
    spy(brake_tests, "_windows")
    spy(pipeline, "fit_adhesion_curves")
    spy(pipeline, "save_surface")
    t, v, om, p, _ = mini_run
    log = braking_log_from_frame(minisim.log_frame(t, v, om, p), warn=False)
    run = pipeline.run_identification(log, mini_vehicle, tmp_path, threads=1,
                                      progress=events.append)
    labels = [e for e in events if e in pipeline.STAGES]
    assert labels == list(pipeline.STAGES[1:])

    def first(name):
        return events.index(name)

    def last(name):
        return len(events) - 1 - events[::-1].index(name)

    assert first("normal loads and adhesion (eqs. 10-13)") < first("_axle_adhesion")
    assert last("_axle_adhesion") < first("identification windows") < first("_windows")
    assert last("_windows") < first("surface")
    assert first("surface") < first("fitted curves") < first("fit_adhesion_curves")
    assert last("fit_adhesion_curves") < first("figures")
    assert last("save_surface") < first("figures") < first("summary")
    # windows.csv is a CSV that pandas reads back as written
    back = pd.read_csv(run.paths["windows"])
    assert list(back.columns) == list(run.ident.windows.columns)
    assert len(back) == len(run.ident.windows) > 0
    assert set(back["phase"]) <= {"loss", "recovery"}


def test_write_frame_csv_round_trips_awkward_values(tmp_path):
    frame = pd.DataFrame({"phase": ["loss", 'a "quoted", value', "x\ny"],
                          "t": [0.1, 1e-300, 1149.0], "n": [1, 2, 3]})
    back = pd.read_csv(pipeline.write_frame_csv(frame, tmp_path / "a.csv"))
    pd.testing.assert_frame_equal(back, frame, check_dtype=False)
    empty = pd.DataFrame(columns=["axle", "phase", "start_time"])
    back = pd.read_csv(pipeline.write_frame_csv(empty, tmp_path / "b.csv"))
    assert list(back.columns) == list(empty.columns) and len(back) == 0
