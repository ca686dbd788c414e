"""The base of every schema model: unknown keys are errors, not silently ignored; nan and inf are refused."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict


class StrictModel(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)  # nan and inf are never a valid quantity


def exactly_one(model: BaseModel, *fields: str) -> None:
    """For ``model_validator``s: exactly one of ``fields`` must be given (not None)."""
    if sum(getattr(model, name) is not None for name in fields) != 1:
        raise ValueError(f"give exactly one of {' or '.join(fields)}")
