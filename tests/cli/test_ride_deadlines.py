import pytest

from explaindrive.cli.ride import module_deadlines
from explaindrive.ride.config import RideConfig


def test_deadlines_set_the_three_modules() -> None:
    fields = module_deadlines("5,2.5,6")
    assert fields == {
        "interpret_deadline_s": 5.0,
        "decide_deadline_s": 2.5,
        "explain_deadline_s": 6.0,
    }
    cfg = RideConfig(**fields)
    assert (cfg.interpret_deadline_s, cfg.decide_deadline_s, cfg.explain_deadline_s) == (5, 2.5, 6)
    assert module_deadlines(None) == {}


@pytest.mark.parametrize("text", ["1,2", "1,2,3,4", "a,b,c", ""])
def test_deadlines_need_three_numbers(text: str) -> None:
    with pytest.raises(ValueError, match="--deadlines takes INTERPRET,DECIDE,EXPLAIN"):
        module_deadlines(text)
