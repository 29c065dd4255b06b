"""Readable messages for pydantic validation errors: one line per problem, naming the dotted
key and the rule it breaks.

Used for every input table of the project (material files, case files), so that both speak
the same language:

>>> from pydantic import BaseModel, ConfigDict, Field, ValidationError
>>> class Table(BaseModel):
...     model_config = ConfigDict(extra="forbid")
...     length: float = Field(gt=0.0)
>>> try:
...     Table.model_validate({"length": -1.0, "lenght": 2.0})
... except ValidationError as err:
...     print(format_errors(err, Table))
length = -1.0: must be > 0.0
unknown key 'lenght' (did you mean 'length'?)
"""
from __future__ import annotations

import difflib
import typing
from typing import Annotated, Any

from pydantic import BaseModel, ValidationError

__all__ = ["format_errors", "model_class"]

_RULES = {
    "greater_than": "must be > {gt}",
    "greater_than_equal": "must be >= {ge}",
    "less_than": "must be < {lt}",
    "less_than_equal": "must be <= {le}",
    "int_type": "must be an integer",
    "int_from_float": "must be an integer",
    "float_type": "must be a number",
    "float_parsing": "must be a number",
    "string_type": "must be a string",
    "bool_type": "must be true or false",
    "list_type": "must be an array",
    "dict_type": "must be a table",
    "model_type": "must be a table",
    "model_attributes_type": "must be a table",
    "missing": "is required",
    "string_pattern_mismatch": "must match {pattern}",
    "too_short": "needs at least {min_length} entries",
    "too_long": "takes at most {max_length} entries",
}


def format_errors(exc: ValidationError, root: type[BaseModel],
                  variants: dict[str, dict[str, type[BaseModel]]] | None = None) -> str:
    """All problems of ``exc`` (raised validating ``root``), one line each, duplicates dropped.

    Parameters
    ----------
    exc : pydantic.ValidationError
    root : pydantic model class that was validated (finds the known keys of a table).
    variants : dict, optional
        ``{key: {tag: model}}`` for tables that are a union tagged by ``kind``; pydantic puts
        the tag into the location, the message does not.

    A rule of a whole table may write ``@`` for the table's dotted key (``@.f1``: its key f1).
    """
    lines = []
    for err in exc.errors(include_url=False):
        line = _format_error(err, root, variants or {})
        if line not in lines:
            lines.append(line)
    return "\n".join(lines)


def model_class(annotation):
    """The pydantic model class inside a field annotation (``X | None``, ``Annotated``), or None."""
    for arg in (annotation, *typing.get_args(annotation)):
        if isinstance(arg, type) and issubclass(arg, BaseModel):
            return arg
        if typing.get_origin(arg) is Annotated:
            found = model_class(typing.get_args(arg)[0])
            if found is not None:
                return found
    return None


def _dotted(loc) -> str:
    parts = []
    for item in loc:
        if isinstance(item, int):
            parts[-1] = f"{parts[-1]}[{item}]" if parts else f"[{item}]"
        else:
            parts.append(str(item))
    return ".".join(parts)


def _model_at(loc, root, variants) -> type[BaseModel] | None:
    """The model class owning the table at ``loc`` (None if it is not a table)."""
    cls: Any = root
    for i, item in enumerate(loc):
        if isinstance(item, int) or cls is None:
            return None
        if i == 1 and loc[0] in variants:
            cls = variants[loc[0]].get(item)
            continue
        field = cls.model_fields.get(item)
        cls = None if field is None else model_class(field.annotation)
    return cls


def _clean_loc(loc, variants) -> tuple:
    loc = list(loc)
    if len(loc) >= 2 and loc[0] in variants and loc[1] in variants[loc[0]]:
        loc.pop(1)
    # an array of tagged tables (``"contact.body[]"``): the tag follows the index
    for i in range(len(loc) - 1, 1, -1):
        if isinstance(loc[i - 1], int) and loc[i] in variants.get(_dotted(loc[:i - 1]) + "[]", ()):
            loc.pop(i)
    return tuple(loc)


def _format_error(err: dict, root, variants) -> str:
    raw_loc = tuple(err["loc"])
    loc = _clean_loc(raw_loc, variants)
    key = _dotted(loc)
    kind = err["type"]
    if kind == "extra_forbidden":
        owner = _model_at(raw_loc[:-1], root, variants)
        known = list(owner.model_fields) if owner is not None else []
        guess = difflib.get_close_matches(str(loc[-1]), known, n=2, cutoff=0.7)
        hint = (" (did you mean " + " or ".join(f"'{g}'" for g in guess) + "?)") if guess else (
            f"; known keys: {', '.join(known)}" if known else "")
        return f"unknown key '{key}'{hint}"
    if kind in ("value_error", "assertion_error"):
        msg = str(err.get("ctx", {}).get("error", err["msg"]))
        if "@" in msg:
            return msg.replace("@.", f"{key}." if key else "").replace("@", key or "the file")
        if isinstance(err.get("input"), dict):   # a rule of the whole table
            return f"{key}: {msg}" if key else msg
        return f"{key} = {_show(err.get('input'))}: {msg}" if key else msg
    if kind == "union_tag_invalid":
        tag = str(err["ctx"].get("discriminator", "'kind'")).strip("'")
        return (f"{key}.{tag} = {_show(err['ctx']['tag'])}: must be one of "
                f"{err['ctx']['expected_tags']}")
    if kind == "union_tag_not_found":
        tags = ", ".join(variants.get(key, {})) or err["ctx"].get("discriminator", "")
        return f"{key}.kind is required (one of {tags})"
    if kind == "literal_error":
        return f"{key} = {_show(err.get('input'))}: must be one of {err['ctx']['expected']}"
    if kind == "missing":
        return f"{key} is required"
    rule = _RULES.get(kind)
    if rule is not None:
        try:
            rule = rule.format(**err.get("ctx", {}))
        except (KeyError, IndexError):
            pass
    else:
        rule = err["msg"][0].lower() + err["msg"][1:]
    return f"{key} = {_show(err.get('input'))}: {rule}"


def _show(value) -> str:
    if isinstance(value, str):
        return repr(value)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, dict):
        return "{...}"
    return str(value)
