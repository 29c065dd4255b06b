"""What every case table shares: quantities with units, strict tables, one-line rules.

A number in SI or a string with units (``"5 cm"``, converted with pint) for every
dimensional key (:func:`Q`); every table (:class:`_Section`) rejects unknown keys.
"""
from __future__ import annotations

import math
from typing import Annotated

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
)

from constitutive.units import parse_quantity, ureg

__all__ = ['Q']


# --------------------------------------------------------------------------- quantities
def _ureg():
    return ureg


def _quantity(unit: str):
    """Before-validator: accept a number (SI) or a string with units convertible to ``unit``."""

    def convert(value):
        if isinstance(value, str):
            import pint


            try:
                si = float(parse_quantity(value).to(unit).magnitude)
                if not math.isfinite(si):
                    raise ValueError(f"out of range in {unit or 'dimensionless'} units")
                return si
            except (pint.errors.PintError, ValueError) as exc:
                raise ValueError(
                    f"cannot read {value!r} as a quantity in {unit or 'dimensionless'} units ({exc})"
                ) from None
        return value

    return BeforeValidator(convert)


def Q(unit: str, **field_kwargs):
    """A float field in SI ``unit`` that also accepts unit strings (``"5 cm"``)."""
    return Annotated[float, _quantity(unit), Field(**field_kwargs)]


_CONFIG = ConfigDict(extra="forbid", strict=True, use_attribute_docstrings=True, allow_inf_nan=False)


class _Section(BaseModel):
    model_config = _CONFIG


def _rule(message: str):
    """Cross-key rule error; ``@.`` in ``message`` becomes the dotted path of the table."""
    return ValueError(message)
