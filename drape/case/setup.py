"""A case built on a set-up: ``setup = "cusick"`` (the bundled ``cases/setups/cusick.toml``) or
``setup = "my_tester.toml"`` (a file beside the case) at the top of a case file (read by
:func:`drape.case.case.read_case_data`).

A set-up is a case file without the fabric: the tester, the mesh, how the specimen is worked
(supports, loads, contact), the solver and the stop rule. A case that names one gives only
what is its own (``[case]``, the fabric, the measurement, a different tester's diameters) and
takes the rest from the set-up, so every case on it is worked the same way. The merge is by
table: a value the case gives replaces the set-up's, a table the case gives is merged key by
key, an array replaces the set-up's array whole.

The fabric is the case's alone, with one exception: a KES sheet (``[material.kes]``) takes
the set-up's ``[material.kes]`` values for the keys it does not give. That is where a set-up
states what it stands in for a sheet that omits a value (the in-plane shear G, say). A fabric
given any other way (``name``, ``path``) takes nothing from the set-up's material.

>>> setup = {"solver": {"dt": 0.05, "t_end": 80.0}, "material": {"kes": {"G": 0.45}},
...          "contact": {"dhat": "1 mm", "body": [{"name": "support"}]}}
>>> case = {"case": {"name": "x"}, "solver": {"t_end": 10.0},
...         "material": {"kes": {"B_warp": 0.1, "B_weft": 0.1}}}
>>> merged = merge_setup(setup, case)
>>> merged["solver"], merged["material"]["kes"]["G"], merged["contact"]["dhat"]
({'dt': 0.05, 't_end': 10.0}, 0.45, '1 mm')
>>> merge_setup(setup, {"material": {"name": "fabric1"}})["material"]
{'name': 'fabric1'}
"""
from __future__ import annotations

import copy

__all__ = ["SETUP_KEY", "SETUPS", "merge_setup"]

#: The top-level key of a case file that names its set-up.
SETUP_KEY = "setup"

#: The folder of the bundled set-ups, in ``cases/``: ``setup = "cusick"`` is ``setups/cusick.toml``.
SETUPS = "setups"


def _merge(base: dict, over: dict) -> dict:
    out = copy.deepcopy(base)
    for key, value in over.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = _merge(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out


def merge_setup(setup: dict, case: dict) -> dict:
    """``case`` on ``setup``: the case's values win, tables merge key by key, and the fabric is
    the case's (a KES sheet takes the set-up's ``[material.kes]`` for the keys it omits)."""
    base = {k: v for k, v in setup.items() if k != "material"}
    merged = _merge(base, {k: v for k, v in case.items() if k != "material"})
    material = copy.deepcopy(case.get("material", {}))
    sheet = material.get("kes")
    if isinstance(sheet, dict):
        material["kes"] = {**setup.get("material", {}).get("kes", {}), **sheet}
    if "material" in case or "material" in setup:
        merged["material"] = material
    return merged
