"""The ``--help-case`` text: every table and key of a case file, read from its JSON schema.

Types, defaults and whether a key is required come from pydantic's JSON schema of
:class:`drape.case.case.Case`; meanings from the docstrings of the tables and their keys (the
schema's ``description``), so the help cannot drift from what is validated.
"""
from __future__ import annotations

import json

__all__ = ["describe"]

_INTRO = [
    "Case file schema (TOML). Numbers are SI, except in [material.kes] (the units a KES sheet",
    'prints); a dimensional number may also be a string with units, e.g. length = "5 cm".',
    "Unknown keys are errors.",
    "",
    'setup = "cusick"  (top of the file, before any table; optional)',
    "    The set-up the case is built on: a bundled set-up's name (cusick: cases/setups/cusick.toml,",
    "    the Cusick tester as it is worked) or a .toml file beside the case. Its tables are taken",
    "    under the case's own: the case's values win, tables merge key by key, arrays are replaced;",
    "    a [material.kes] sheet takes the set-up's [material.kes] values for the keys it omits.",
    "",
]


def describe(model) -> str:
    """Help text of the pydantic model ``model`` (a whole case file), one block per table.

    >>> from drape.case.case import Case
    >>> text = describe(Case)
    >>> "[solver]" in text and "  dt : number  (required)" in text
    True
    """
    schema = model.model_json_schema()
    defs = schema.get("$defs", {})
    lines = list(_INTRO)
    for name, prop in schema["properties"].items():
        table = _resolve(prop, defs)
        if "oneOf" in table:
            _variants(name, table, defs, lines)
        else:
            _table(name, table, defs, lines)
    return "\n".join(lines).rstrip() + "\n"


def _resolve(prop: dict, defs: dict) -> dict:
    """The table a property refers to (through ``$ref`` and ``X | None``), else ``prop``."""
    if "$ref" in prop:
        return defs[prop["$ref"].rsplit("/", 1)[-1]]
    for option in prop.get("anyOf", ()):
        if "$ref" in option:
            return _resolve(option, defs)
    return prop


def _is_table(prop: dict, defs: dict) -> bool:
    target = _resolve(prop, defs)
    return target is not prop and "properties" in target


def _head(name: str, table: dict) -> list[str]:
    doc = table.get("description", "").strip().splitlines() or [""]
    head = doc[0]
    if head.startswith(f"[{name}]"):
        head = head[len(name) + 2:].lstrip(" :")
    return [f"[{name}]" + (f"  {head}" if head else "")] + [
        f"    {line.strip()}" for line in doc[1:] if line.strip()]


def _table(prefix: str, table: dict, defs: dict, lines: list[str]) -> None:
    lines.extend(_head(prefix, table))
    nested, arrays = [], []
    required = set(table.get("required", ()))
    for name, prop in table.get("properties", {}).items():
        if _is_table(prop, defs):
            nested.append((name, _resolve(prop, defs)))
            continue
        lines.extend(_key(name, prop, name in required, "  "))
        if "oneOf" in prop.get("items", {}):     # an array of tables, e.g. [[contact.body]]
            arrays.append((name, prop["items"]))
    lines.append("")
    for name, sub in nested:
        _table(f"{prefix}.{name}", sub, defs, lines)
    for name, items in arrays:
        _variants(f"{prefix}.{name}", items, defs, lines, array=True)


def _variants(prefix: str, union: dict, defs: dict, lines: list[str], array: bool = False) -> None:
    """A table whose keys depend on its ``kind`` (or ``shape``: a discriminated union)."""
    key = union.get("discriminator", {}).get("propertyName", "kind")
    lines.append(f"[[{prefix}]]" if array else f"[{prefix}]")
    lines[-1] += f"  the keys depend on {key}:"
    for option in union["oneOf"]:
        variant = _resolve(option, defs)
        doc = variant.get("description", "").strip().splitlines()
        lines += [f"  {doc[0]}"] + [f"    {line.strip()}" for line in doc[1:]] if doc else []
        required = set(variant.get("required", ()))
        for name, prop in variant["properties"].items():
            if name != key:
                lines.extend(_key(name, prop, name in required, "    "))
    lines.append("")


def _key(name: str, prop: dict, required: bool, indent: str) -> list[str]:
    default = "required" if required else _default(prop)
    out = [f"{indent}{name} : {_type(prop)}" + (f"  ({default})" if default else "")]
    out += [f"{indent}    {line.strip()}" for line in prop.get("description", "").strip().splitlines()]
    return out


def _type(prop: dict) -> str:
    if "enum" in prop:
        return " | ".join(json.dumps(v) for v in prop["enum"])
    if "const" in prop:
        return json.dumps(prop["const"])
    if "anyOf" in prop:
        return " | ".join(_type(p) for p in prop["anyOf"] if p.get("type") != "null")
    kind = prop.get("type")
    if kind == "array":
        return f"array of {_type(prop['items'])}" if "items" in prop else "array"
    if kind == "object":
        extra = prop.get("additionalProperties")
        return f"table of {_type(extra)}" if isinstance(extra, dict) else "table"
    if "$ref" in prop:
        return "table"
    return kind or "value"


def _default(prop: dict) -> str:
    if "default" not in prop:
        return ""
    value = prop["default"]
    if isinstance(value, dict):
        return ""
    if value is None:
        return "optional"
    if isinstance(value, str):
        return f'default "{value}"'
    if isinstance(value, bool):
        return f"default {'true' if value else 'false'}"
    return f"default {value!r}"
