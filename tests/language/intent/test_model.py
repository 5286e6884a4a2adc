"""LLM-1's learned model: the adapters' merge, the decision rule, the file, the thresholds."""

from __future__ import annotations

import numpy as np
import pytest

from explaindrive.language.intent.adapter import AdapterSpec, merge
from explaindrive.language.intent.calibration import (
    ask_stop_threshold,
    choose_thresholds,
    curve,
    stop_threshold,
)
from explaindrive.language.intent.model import READINGS, IntentModel, Thresholds
from explaindrive.language.intent.stop_path import names_stop

LAYER = "encoder.layer.0.attention.self.query"


THRESHOLDS = Thresholds(0.6, 0.7)


def _model(thresholds: Thresholds = THRESHOLDS) -> IntentModel:
    a = np.array([[1.0, 0.0, 2.0]], np.float32)  # rank 1, in 3
    b = np.array([[1.0], [0.0]], np.float32)  # out 2
    head_w = np.zeros((len(READINGS), 2), np.float32)
    return IntentModel(
        {LAYER: (a, b)}, AdapterSpec(1, 2.0), head_w, np.zeros(len(READINGS), np.float32),
        thresholds, "0" * 64,
    )  # fmt: skip


def test_merge_adds_the_scaled_low_rank_change() -> None:
    w = np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]], np.float32)
    model = _model()
    merged = merge({f"{LAYER}.weight": w, "other": w}, model.adapters, model.spec)
    # scale 2: B A = [[1, 0, 2], [0, 0, 0]] -> W + 2 B A
    np.testing.assert_array_equal(merged[f"{LAYER}.weight"], [[3, 2, 7], [4, 5, 6]])
    np.testing.assert_array_equal(merged["other"], w)


def test_merge_refuses_an_adapter_that_does_not_fit() -> None:
    model = _model()
    with pytest.raises(ValueError, match="do not fit"):
        merge({f"{LAYER}.weight": np.zeros((2, 4))}, model.adapters, model.spec)
    with pytest.raises(ValueError, match="no weight"):
        merge({"x.weight": np.zeros((2, 3))}, model.adapters, model.spec)


def _p(**probs: float) -> np.ndarray:
    p = np.zeros(len(READINGS))
    for name, v in probs.items():
        p[READINGS.index(name)] = v
    return p


@pytest.mark.parametrize(
    ("probs", "reading", "abstained"),
    [
        ({"stop": 0.7, "fast": 0.3}, "stop", False),  # STOP at its threshold
        ({"stop": 0.69, "none": 0.31}, "none", True),  # STOP below it: no command
        ({"fast": 0.6, "none": 0.4}, "fast", False),  # a command at the threshold
        ({"fast": 0.59, "none": 0.41}, "none", True),  # below it: abstain
        ({"why": 0.5, "fast": 0.3, "none": 0.2}, "why", False),
        ({"yes": 0.9, "no": 0.1}, "yes", False),
    ],
)
def test_decide_gives_a_command_only_above_its_threshold(
    probs: dict[str, float], reading: str, abstained: bool
) -> None:
    r = _model().decide(_p(**probs))
    assert (r.reading, r.abstained) == (reading, abstained)
    assert r.command == (reading if reading in ("fast", "comfort", "stop") else None)


@pytest.mark.parametrize(
    ("probs", "ask"),
    [
        ({"stop": 0.69, "none": 0.31}, True),  # most probable, short of 0.7, within the band
        ({"stop": 0.5, "none": 0.3, "fast": 0.2}, True),  # at the band's floor
        ({"stop": 0.49, "none": 0.3, "fast": 0.21}, False),  # below it: left alone
        ({"stop": 0.45, "none": 0.55}, False),  # not the most probable reading
        ({"stop": 0.7, "none": 0.3}, False),  # read as STOP, not asked about
    ],
)
def test_a_stop_short_of_its_threshold_is_asked_about_within_the_band(
    probs: dict[str, float], ask: bool
) -> None:
    r = _model(Thresholds(0.6, 0.7, 0.5)).decide(_p(**probs))
    assert r.ask_stop is ask
    assert r.command == ("stop" if probs["stop"] >= 0.7 else None)
    # without a band nothing is asked about
    assert not _model().decide(_p(**probs)).ask_stop


def test_the_model_file_round_trips_and_refuses_a_bad_one(tmp_path) -> None:
    model = _model()
    model.save(tmp_path / "m.npz")
    back = IntentModel.load(tmp_path / "m.npz")
    assert back.thresholds == model.thresholds and back.spec == model.spec
    assert back.thresholds.ask_stop is None  # a file without the band: none
    banded = _model(Thresholds(0.6, 0.9, 0.55))
    banded.save(tmp_path / "band.npz")
    assert IntentModel.load(tmp_path / "band.npz").thresholds == Thresholds(0.6, 0.9, 0.55)
    np.testing.assert_array_equal(back.adapters[LAYER][0], model.adapters[LAYER][0])
    assert back.digest() == model.digest()
    (tmp_path / "bad.npz").write_bytes(b"not a zip")
    with pytest.raises(ValueError, match="not a valid intent model"):
        IntentModel.load(tmp_path / "bad.npz")
    with pytest.raises(FileNotFoundError):
        IntentModel.load(tmp_path / "missing.npz")


def test_thresholds_read_no_false_stop_and_bound_false_commands() -> None:
    model = _model()
    # 2,000 lines without a command: one at p(stop) 0.95, one at 0.5; 20 with p(fast)
    # 0.55 and 21 with p(fast) 0.45, the most probable reading of their rows
    rows = [_p(none=1.0)] * 1957 + [_p(stop=0.95, none=0.05), _p(stop=0.5, none=0.5)]
    rows += [_p(fast=0.55, none=0.45)] * 20 + [_p(fast=0.45, none=0.35, why=0.2)] * 21
    labels = ["none"] * 2000
    rows += [_p(fast=0.9, none=0.1), _p(comfort=0.5, none=0.5)]
    labels += ["fast", "comfort"]
    t, report = choose_thresholds(model, np.array(rows), labels)
    # STOP: no STOP request, so the cost is the false STOPs: 2 up to 0.50, 1 up to 0.95,
    # 0 from 0.96
    assert t.stop == pytest.approx(0.96)
    # command: up to 0.45 the 41 fast lines get a command, 2.05 % of 2,000 > 2 %; from
    # 0.46 the 20 at 0.55 (1 %)
    assert t.command == pytest.approx(0.46)
    points = {round(pt.threshold, 2): pt for pt in curve(model, np.array(rows), labels, t.stop)}
    assert points[0.45].false_command == pytest.approx(41 / 2000)
    assert points[0.46].false_command == pytest.approx(20 / 2000)
    assert points[0.46].coverage == pytest.approx(1.0)  # both commands still answered
    assert points[0.46].risk == pytest.approx(20 / 22)  # 20 of the 22 given are wrong
    assert points[0.56].false_command == 0.0
    assert points[0.56].coverage == pytest.approx(0.5)
    # the two lines most probably STOP below 0.96 (0.95, and 0.5 tied with none) are 0.1 %
    # of the lines without a command, within the 0.5 % asked about: asked from the grid's
    # lowest threshold
    assert t.ask_stop == pytest.approx(0.30)
    assert "STOP threshold 0.96, asked about from 0.30, command threshold 0.46" in report
    # two STOP requests at 0.6 and 0.45 do not move it: below 0.96 a line without a
    # command would be read as STOP
    rows += [_p(stop=0.6, none=0.4), _p(stop=0.45, none=0.55)]
    labels += ["stop", "stop"]
    assert choose_thresholds(model, np.array(rows), labels)[0].stop == pytest.approx(0.96)


def test_the_stop_threshold_reads_no_line_without_a_command_as_stop() -> None:
    # 3 of 1,000 lines without a command at p(stop) 0.5: 0.50 reads them as STOP, 0.51 none
    negative = np.array([0.5] * 3 + [0.01] * 997)
    assert stop_threshold(negative) == pytest.approx(0.51)
    # a line at exactly 0.51 is read as STOP at 0.51: the next step of the grid
    assert stop_threshold(np.append(negative, 0.51)) == pytest.approx(0.52)
    # every line below the grid: its lowest threshold
    assert stop_threshold(np.full(10, 0.1)) == pytest.approx(0.30)
    # no threshold of the grid reads none of them: the highest
    assert stop_threshold(np.array([1.0, 1.0])) == pytest.approx(0.99)


def test_the_ask_band_asks_about_at_most_half_a_percent_of_lines_without_a_command() -> None:
    # 1,000 lines without a command: 6 most probably STOP at 0.6, 4 at 0.8, one at p(stop)
    # 0.45 whose most probable reading is why; STOP's threshold 0.9
    rows = [_p(none=1.0)] * 989 + [_p(stop=0.6, none=0.4)] * 6 + [_p(stop=0.8, none=0.2)] * 4
    rows.append(_p(stop=0.45, why=0.55))
    negative = np.ones(len(rows), bool)
    # up to 0.60 ten are asked about (1.0 % > 0.5 %); from 0.61 four (0.4 %)
    assert ask_stop_threshold(_model(), np.array(rows), negative, 0.9) == pytest.approx(0.61)
    # a STOP request at 0.6 is not a line without a command: it does not count
    rows.append(_p(stop=0.6, none=0.4))
    negative = np.append(negative, False)
    assert ask_stop_threshold(_model(), np.array(rows), negative, 0.9) == pytest.approx(0.61)
    # six at 0.89 (0.6 %) under a threshold of 0.9: no band (the STOP threshold itself)
    rows = [_p(none=1.0)] * 994 + [_p(stop=0.89, none=0.11)] * 6
    assert ask_stop_threshold(_model(), np.array(rows), np.ones(1000, bool), 0.9) == pytest.approx(
        0.9
    )


@pytest.mark.parametrize(
    ("text", "named"),
    [
        ("Pull over, I'm going to be sick", True),
        ("please let me out here", True),
        ("drop me off here thanks", True),
        ("This is an emergency!", True),
        ("I can't stop thinking about that film", False),
        ("the pullover is in the boot", False),
    ],
)
def test_the_stop_path_names_its_phrases_only(text: str, named: bool) -> None:
    assert names_stop(text) is named
