"""Strict pydantic base model: unknown keys are rejected with the nearest valid name."""

from __future__ import annotations

import difflib
from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Field, Strict, model_validator

# Strict scalars: TOML has real booleans, integers and floats, so a boolean or a string where
# a number is expected is a mistake (`inertia = true` would otherwise read as K = 1,
# `restitution = "0.5"` as 0.5). Strict floats still take integers (TOML `1` for 1.0).
Float = Annotated[float, Strict()]
Int = Annotated[int, Strict()]
Bool = Annotated[bool, Strict()]
PosFloat = Annotated[float, Strict(), Field(gt=0.0)]
PosInt = Annotated[int, Strict(), Field(gt=0)]


class SceneError(ValueError):
    """Invalid scene: the message names each field, its value and what is allowed."""

    def __init__(self, source: str, problems: list[str]):
        self.source = source
        self.problems = problems
        lines = "\n".join(f"  - {p}" for p in problems)
        super().__init__(f"invalid scene {source}:\n{lines}")


def nearest(name: str, allowed: list[str]) -> str | None:
    """The allowed name closest to ``name`` (None when nothing is close)."""
    found = difflib.get_close_matches(name, allowed, n=1, cutoff=0.5)
    return found[0] if found else None


class StrictModel(BaseModel):
    """Base of every scene section: frozen, no unknown keys, helpful messages."""

    # allow_inf_nan=False: TOML has nan and inf literals; no scene number may be non-finite
    model_config = ConfigDict(
        extra="forbid", frozen=True, validate_default=True, allow_inf_nan=False
    )

    @model_validator(mode="before")
    @classmethod
    def _reject_unknown_keys(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            return data
        allowed = sorted(cls.model_fields)
        problems = []
        for key in data:
            if key in cls.model_fields:
                continue
            hint = nearest(str(key), allowed)
            text = f"unknown key {key!r}"
            text += f"; did you mean {hint!r}?" if hint else ""
            problems.append(text + f" (allowed: {', '.join(allowed)})")
        if problems:
            raise ValueError("; ".join(problems))
        return data
