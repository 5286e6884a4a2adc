"""One-line messages for pydantic validation errors."""

from __future__ import annotations

import pytest
from pydantic import BaseModel, ValidationError

from explaindrive.validation import describe_errors


class Inner(BaseModel):
    v: float


class Outer(BaseModel):
    inner: Inner
    n: int


def test_every_field_is_named_with_its_path() -> None:
    with pytest.raises(ValidationError) as err:
        Outer.model_validate({"inner": {"v": "fast"}})
    text = describe_errors(err.value)
    assert text.split("; ")[0].startswith("inner.v: Input should be a valid number")
    assert text.split("; ")[1] == "n: Field required"


def test_whole_object_errors_use_the_root_name() -> None:
    with pytest.raises(ValidationError) as err:
        Outer.model_validate([1, 2])
    assert describe_errors(err.value).startswith("<root>: Input should be")
    assert describe_errors(err.value, root="line").startswith("line: Input should be")
