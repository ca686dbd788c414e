"""The base of every schema model: unknown keys are errors, not silently ignored; nan and inf are refused."""

from __future__ import annotations

import types
import typing
from typing import Any

from pydantic import BaseModel, ConfigDict, model_validator


class StrictModel(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)  # nan and inf are never a valid quantity

    @model_validator(mode="before")
    @classmethod
    def _no_booleans_for_numbers(cls, data: Any) -> Any:
        """YAML's true and false are not 1 and 0: pydantic would take them as numbers."""
        if isinstance(data, dict):
            for name, field in cls.model_fields.items():
                value = data.get(field.alias or name)
                if isinstance(value, bool) and _numeric(field.annotation):
                    raise ValueError(f"{name}: a number is needed, not {str(value).lower()}")
        return data


def _numeric(annotation: Any) -> bool:
    """Whether a field takes a number (int or float, possibly optional) and not a boolean."""
    if annotation in (int, float):
        return True
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        options = [a for a in typing.get_args(annotation) if a is not type(None)]
        return bool(options) and all(a in (int, float) for a in options)
    return False


def exactly_one(model: BaseModel, *fields: str) -> None:
    """For ``model_validator``s: exactly one of ``fields`` must be given (not None)."""
    if sum(getattr(model, name) is not None for name in fields) != 1:
        raise ValueError(f"give exactly one of {' or '.join(fields)}")
