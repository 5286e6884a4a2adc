import pytest
from pydantic import ValidationError

from explaindrive.language.explanation.history import HistoryTracker, RideHistory


def test_slow_and_standing_time_count_up_and_reset() -> None:
    t = HistoryTracker()
    # limit 13.9: slow at or below 10.9 m/s, standing at or below 0.5 m/s
    seen = [(12.0, 0, 0), (10.9, 1, 0), (5.0, 2, 0), (0.4, 3, 1), (0.0, 4, 2), (11.0, 0, 0)]
    for v, slow, stopped in seen:
        h = t.update(v, 13.9)
        assert (h.slow_s, h.stopped_s) == (slow, stopped)


def test_the_drop_is_measured_against_the_fastest_of_the_last_3_s() -> None:
    t = HistoryTracker()
    drops = [t.update(v, 13.9).drop_mps for v in (12.0, 11.0, 10.0, 9.0, 8.0, 8.0, 8.0)]
    # window of 4 readings (now and 3 s back): 12-9 = 3 at the 4th, 11-8 = 3, 10-8, 9-8, 8-8
    assert drops == [0.0, 1.0, 2.0, 3.0, 3.0, 2.0, 1.0]


def test_history_rejects_negative_times_and_unknown_keys() -> None:
    with pytest.raises(ValidationError):
        RideHistory(slow_s=-1.0)
    with pytest.raises(ValidationError):
        RideHistory.model_validate({"slow": 1.0})
