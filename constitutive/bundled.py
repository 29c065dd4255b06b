"""Where the bundled cases are: the material library, the validation set, the examples.

One copy of the files exists: the ``cases/`` folder of the source tree. A wheel ships that
folder as the package ``fabric_drape_cases`` (``[tool.setuptools] package-dir`` in
``pyproject.toml``), so an installed copy finds the same files through
:mod:`importlib.resources`. In a source tree (an editable install or a checkout on
``sys.path``) the ``cases/`` folder beside the code wins, so that the files one edits are the
files one runs.

>>> sorted(p.name for p in cases_dir("materials").glob("fabric1*.toml"))
['fabric1.toml']
"""
from __future__ import annotations

import importlib.resources
from pathlib import Path

__all__ = ["PACKAGE", "cases_dir"]

#: Import name of the installed ``cases/`` folder.
PACKAGE = "fabric_drape_cases"

_SOURCE_TREE = Path(__file__).resolve().parents[1] / "cases"


def cases_dir(*parts: str) -> Path:
    """The bundled ``cases`` folder, or a folder inside it (``cases_dir("materials")``)."""
    if (_SOURCE_TREE / "materials").is_dir():
        root = _SOURCE_TREE
    else:
        # installed from a wheel: the package's files are on disk (wheels are unpacked)
        root = Path(str(importlib.resources.files(PACKAGE)))
    return root.joinpath(*parts)
