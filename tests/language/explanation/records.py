"""State records for the rule-engine and explainer tests."""

from __future__ import annotations

from typing import Any

from explaindrive.language.explanation.summary import StateRecord


def state_record(request: str, action: int, **state: Any) -> StateRecord:
    """A record of ``request`` and speed change ``action`` [m/s]; ``state`` adds to or
    replaces the defaults ``v_ego`` 10 m/s and ``v_lim`` 13.9 m/s."""
    base: dict[str, Any] = {"v_ego": 10.0, "v_lim": 13.9, **state}
    return StateRecord.model_validate({"request": request, "action": action, "state": base})
