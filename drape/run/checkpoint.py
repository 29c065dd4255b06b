"""A run's checkpoint: its last converged step, enough to continue it as if never stopped.

``checkpoint.npz`` in the run folder is rewritten after every converged step, atomically (a
temporary file in the same folder, then ``os.replace``: :func:`drape.run.atomic.atomic_write`),
so a run killed at any moment leaves the checkpoint of a converged step. It holds

- the integrator's state: time, ``u``, ``v``, ``a`` (and the HHT force of the step, when kept),
  the size of the last step and the step-size control (``state.*``, ``run["integrator"]``);
- the model's committed state (``model.*``, from ``model.state_dict()``): every quadrature
  point's law state, friction states included, the committed kinematics the model books
  dissipated work from, the booked works, the load scale and the load time;
- the runner's counters (``run``): steps, VTU files and history rows written so far, the
  output schedule, the settling count and the wall time used.

Loads and the seeded fold perturbation are functions of time rebuilt from the case
(``case.resolved.toml``), so they need no state of their own.
"""
from __future__ import annotations

import json
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from drape.run.atomic import atomic_write
from drape.solvers.newmark import NewmarkState

__all__ = ["CHECKPOINT", "Checkpoint", "CheckpointError", "write_checkpoint", "read_checkpoint"]

#: File name of the checkpoint in a run folder.
CHECKPOINT = "checkpoint.npz"


@dataclass
class Checkpoint:
    """The saved step: integrator ``state`` (a ``NewmarkState``), ``model`` state, ``run`` counters."""

    state: object
    model: dict
    run: dict


def write_checkpoint(directory, state, model_state: dict, run: dict) -> Path:
    """Write ``directory/checkpoint.npz`` atomically; return its path.

    >>> from types import SimpleNamespace as NS
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = write_checkpoint(d, NS(t=0.5, u=np.ones(2), v=np.zeros(2), a=np.zeros(2)),
    ...                          {"warp.kappa": np.arange(3.0)}, {"step": 7})
    ...     ck = read_checkpoint(d)
    >>> ck.state.t, ck.state.u.tolist(), ck.model["warp.kappa"].tolist(), ck.run
    (0.5, [1.0, 1.0], [0.0, 1.0, 2.0], {'step': 7})
    """
    directory = Path(directory)
    arrays = {"state.t": np.array(float(state.t)), "state.u": state.u, "state.v": state.v,
              "state.a": state.a, "run": np.array(json.dumps(run))}
    if getattr(state, "force", None) is not None:
        arrays["state.force"] = state.force
    arrays.update({f"model.{k}": np.asarray(v) for k, v in model_state.items()})
    path = directory / CHECKPOINT

    def write(tmp: Path) -> None:
        with open(tmp, "wb") as fh:   # a file object: np.savez would add ".npz" to a name
            np.savez(fh, **arrays)

    return atomic_write(path, write)


def read_checkpoint(directory) -> Checkpoint:
    """The checkpoint of the run in ``directory``.

    Raises
    ------
    CheckpointError
        When the folder has no checkpoint, or its file is not one (empty, truncated, another
        file under its name); the message says which.
    """
    path = Path(directory) / CHECKPOINT
    if not path.exists():
        raise CheckpointError(f"{path}: no checkpoint (was the run started by this version, in "
                              f"this folder?)")
    try:
        return _read(path)
    except OSError:
        raise
    except Exception as exc:  # numpy's and zipfile's errors for what is no .npz of ours
        raise CheckpointError(f"{path} is not a readable checkpoint ({type(exc).__name__}); run "
                              f"the case again without --resume") from None


class CheckpointError(ValueError):
    """No checkpoint, or a file that is not one (the message says which)."""


def _read(path: Path) -> Checkpoint:
    with np.load(path, allow_pickle=False) as data:
        arrays = {k: data[k] for k in data.files}
    state = NewmarkState(float(arrays.pop("state.t")), arrays.pop("state.u"), arrays.pop("state.v"),
                         arrays.pop("state.a"))
    if "state.force" in arrays:
        state.force = arrays.pop("state.force")
    run = json.loads(str(arrays.pop("run")))
    if not isinstance(run, dict):
        raise TypeError("its runner counters are not a table")
    model = {k[len("model."):]: v for k, v in arrays.items() if k.startswith("model.")}
    return Checkpoint(state, model, run)
