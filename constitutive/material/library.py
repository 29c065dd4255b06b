"""The bundled material library (``cases/materials/*.toml``) and material files by path.
"""
from __future__ import annotations

import tomllib
from pathlib import Path

from pydantic import ValidationError

from constitutive.bundled import cases_dir
from constitutive.material.fabric import FabricMaterial, MaterialError
from constitutive.material.spec import MaterialSpec, material_from_spec
from constitutive.schema_errors import format_errors

__all__ = ['available_materials', 'load_material']


def available_materials() -> list[str]:
    """Names of the bundled materials (``cases/materials/*.toml``)."""
    return sorted(p.stem for p in cases_dir("materials").glob("*.toml"))


def _resolve(name_or_path) -> Path:
    p = Path(name_or_path)
    if p.suffix == ".toml" or p.exists() or len(p.parts) > 1:
        if not p.is_file():
            raise MaterialError(f"material file {p} does not exist")
        return p
    p = cases_dir("materials") / f"{name_or_path}.toml"
    if not p.is_file():
        raise MaterialError(f"unknown material {name_or_path!r}; bundled: {', '.join(available_materials())} "
                            "(or give a path to a .toml file)")
    return p


def load_material(name_or_path) -> FabricMaterial:
    """Read a material TOML (KES units) and return it in SI.

    Parameters
    ----------
    name_or_path : str or Path
        A bundled name (``"fabric1"``, ``"fabric2"``, ``"kes_example"``; see
        :func:`available_materials`) or the path of a ``.toml`` file.

    Raises
    ------
    MaterialError
        Unknown name, TOML syntax error, unknown key, wrong type or a broken
        rule — the message names the file, the key and the rule.

    Examples
    --------
    >>> load_material("kes_example").warp.friction.f2
    0.0
    >>> load_material("no-such-fabric")
    Traceback (most recent call last):
    ...
    constitutive.material.fabric.MaterialError: unknown material 'no-such-fabric'; bundled: fabric1, fabric2, fabric2-table4.14, kes_example (or give a path to a .toml file)
    """
    path = _resolve(name_or_path)
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as err:
        raise MaterialError(f"{path.name}: TOML syntax error: {err}") from None
    try:
        spec = MaterialSpec.model_validate(data)
    except ValidationError as err:
        raise MaterialError("\n".join(f"{path.name}: {line}" for line in
                                      format_errors(err, MaterialSpec).splitlines())) from None
    return material_from_spec(spec, path.name)
