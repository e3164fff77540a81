"""Trajectory <-> files and tables: npz (every field, loaded back by Trajectory.load), csv, pandas;
the same npz layout for an EnsembleResult (field_arrays, save_fields, load_fields, from_fields).

The npz holds each array field under its name (t, q, v, energy, ..., events as a structured array
when the run located any), each saved field under its own name (a width-1 field as (S,), as the
writers always did, so existing readers keep working), and ``meta``: a JSON text with every other
field (method, h, model, params, coords, warnings, source, ...) and the saved fields' names and
widths. Fields are found from the dataclass, so a field added to Trajectory round-trips without
an edit here when it is an array, a dict of arrays, or JSON-able.
"""

from __future__ import annotations

import dataclasses
import json
import zipfile
import zlib
from pathlib import Path

import numpy as np

from ..errors import LagrangeGenError

FORMAT = 1
#: The kinds of file save_fields writes, and the reader of each (named in a refusal).
TRAJECTORY, ENSEMBLE = "trajectory", "ensemble"
READERS = {TRAJECTORY: "Trajectory.load", ENSEMBLE: "EnsembleResult.load"}
# what the CLI's readers (and older files) expect even when the method saved none
_ALWAYS = ("element_state", "multipliers")


def write_npz(traj, path):
    """Write every field of ``traj`` to ``path`` (.npz)."""
    arrays, meta = field_arrays(traj)
    for name in _ALWAYS:
        arrays.setdefault(name, getattr(traj, name))
    # the keys older readers use
    legacy = dict(param_names=np.array(list(traj.params), dtype=str),
                  param_values=np.array(list(traj.params.values()), dtype=float),
                  method=traj.method, h=traj.h, model=traj.model, n_steps=traj.n_steps,
                  coords=np.array(traj.coords, dtype=str),
                  element_names=np.array(traj.element_names, dtype=str),
                  constraint_names=np.array(traj.constraint_names, dtype=str))
    save_fields(path, meta, {**legacy, **arrays})


def field_arrays(obj, kind=TRAJECTORY):
    """(arrays, meta) of a dataclass ``obj`` (a Trajectory, an EnsembleResult): each array field
    under its name; ``saved`` ({name: (..., width)}) each under its own name, a width-1 field
    without its last axis; a dict of arrays as "field.key"; every other field in ``meta`` (JSON),
    with the saved fields' names and widths and the ``kind`` of file."""
    arrays, meta = {}, {"format": FORMAT, "kind": kind, "dict_arrays": {}}
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        if f.name == "saved":
            meta["saved"] = [[name, a.shape[-1]] for name, a in value.items()]
            arrays.update({name: a[..., 0] if a.shape[-1] == 1 else a
                           for name, a in value.items()})
        elif isinstance(value, np.ndarray):
            arrays[f.name] = value
        elif value and isinstance(value, dict) and all(isinstance(a, np.ndarray)
                                                         for a in value.values()):
            meta["dict_arrays"][f.name] = list(value)
            arrays.update({f"{f.name}.{k}": a for k, a in value.items()})
        else:
            meta[f.name] = value
    return arrays, meta


def save_fields(path, meta, arrays):
    """The .npz of field_arrays' (arrays, meta); its folder made when missing."""
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    np.savez(path, meta=json.dumps(meta, default=_plain), **arrays)


def _plain(value):
    """JSON for numpy scalars and small arrays inside metadata."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not JSON serializable")


def load_fields(path, kind):
    """{name: array} of a .npz; LagrangeGenError naming the file when it cannot be read
    (unreadable, truncated or corrupted: zip, compression) or when its metadata says it holds
    another kind of file (a trajectory's has no kind: files of older writers)."""
    try:
        # Opened here so that it is closed whatever np.load makes of it (a file that is not a
        # zip is left open by numpy, and a ResourceWarning line follows later).
        with open(path, "rb") as fh, np.load(fh, allow_pickle=False) as data:
            data = {k: data[k] for k in data.files}
    except (OSError, ValueError, EOFError, TypeError, AttributeError, zipfile.BadZipFile,
            zlib.error) as exc:        # TypeError: a .npy (an array, not an archive)
        raise LagrangeGenError(f"{path}: cannot read as {'an' if kind == ENSEMBLE else 'a'} "
                               f"{kind} .npz ({type(exc).__name__}: {_first_line(exc)})") from None
    written = TRAJECTORY
    if "meta" in data:
        try:
            written = json.loads(str(data["meta"])).get("kind", TRAJECTORY)
        except (ValueError, AttributeError):
            written = kind            # damaged metadata: the reader says so
    if written != kind:
        raise LagrangeGenError(f"{path}: holds {'an' if written == ENSEMBLE else 'a'} {written}, "
                               f"not {'an' if kind == ENSEMBLE else 'a'} {kind}: "
                               f"{READERS.get(written, 'its writer')} reads it")
    return data


def read_npz(cls, path):
    """The Trajectory (class ``cls``) written by write_npz; LagrangeGenError naming the file
    when it is not one: unreadable, truncated or corrupted (zip, compression), metadata that is
    not the writer's, or arrays whose lengths disagree."""
    data = load_fields(path, TRAJECTORY)
    try:
        traj = _read_legacy(cls, path, data) if "meta" not in data else from_fields(cls, data)
    except LagrangeGenError:
        raise
    except (ValueError, KeyError, TypeError, IndexError, AttributeError) as exc:
        raise LagrangeGenError(f"{path}: not a trajectory written by lagrange-gen (its metadata "
                               f"or arrays are damaged: {type(exc).__name__}: "
                               f"{_first_line(exc)})") from None
    _check_lengths(path, traj)
    return traj


def _first_line(exc):
    return (str(exc).splitlines() or [""])[0]


def from_fields(cls, data):
    """The dataclass ``cls`` from the arrays and meta of field_arrays (load_fields' dict)."""
    meta = json.loads(str(data["meta"]))
    if not isinstance(meta, dict):
        raise TypeError(f"meta is a {type(meta).__name__}, not a dict")
    kwargs = {}
    for f in dataclasses.fields(cls):
        if f.name == "saved":
            kwargs["saved"] = {name: data[name][..., None] if width == 1 else data[name]
                               for name, width in meta["saved"]}
        elif f.name in meta["dict_arrays"]:
            kwargs[f.name] = {k: data[f"{f.name}.{k}"] for k in meta["dict_arrays"][f.name]}
        elif f.name in meta:         # before data: the legacy keys repeat method, h, model, ...
            value = meta[f.name]
            if str(f.type).startswith("tuple") and isinstance(value, list):
                value = tuple(value)         # JSON has lists only
            kwargs[f.name] = value
        elif f.name in data:
            kwargs[f.name] = data[f.name]
    return cls(**kwargs)


def _check_lengths(path, traj):
    """Refuse a trajectory whose per-row arrays do not have one row per time, or whose q, v
    do not have one column per coordinate."""
    t = np.asarray(traj.t)
    if t.ndim != 1:
        raise LagrangeGenError(f"{path}: t has shape {t.shape}, not (S,)")
    rows, n = len(t), len(traj.coords)
    for name in ("q", "v"):
        arr = np.asarray(getattr(traj, name))
        if arr.shape != (rows, n):
            raise LagrangeGenError(f"{path}: {name} has shape {arr.shape}, not ({rows}, {n}) for "
                                   f"{rows} times and the coordinates {', '.join(traj.coords)}")
    for name in ("energy", "newton_iters", "newton_residual"):
        arr = np.asarray(getattr(traj, name))
        if arr.shape != (rows,):
            raise LagrangeGenError(f"{path}: {name} has shape {arr.shape}, not ({rows},)")
    for name, arr in traj.saved.items():
        if len(arr) != rows:
            raise LagrangeGenError(f"{path}: saved field {name} has {len(arr)} rows for {rows} times")


def _read_legacy(cls, path, data):
    """A file of the writer before ``meta`` (no events, warnings or source)."""
    need = ("t", "q", "v", "energy", "method", "h", "model", "coords")
    missing = [k for k in need if k not in data]
    if missing:
        raise LagrangeGenError(f"{path}: not a lagrange-gen trajectory (no {', '.join(missing)})")
    known = ("multipliers", "constraint_error", "velocity_constraint_error", "element_state")
    saved = {k: data[k].reshape(len(data["t"]), -1) for k in known
             if k in data and data[k].size}
    n = len(data["t"])
    return cls(t=data["t"], q=data["q"], v=data["v"], energy=data["energy"],
               newton_iters=data.get("newton_iters", np.zeros(n)),
               newton_residual=data.get("newton_residual", np.zeros(n)),
               method=str(data["method"]), h=float(data["h"]), model=str(data["model"]),
               params=dict(zip(data["param_names"].tolist(), data["param_values"].tolist())),
               coords=tuple(data["coords"].tolist()), n_steps=int(data.get("n_steps", n - 1)),
               saved=saved, element_names=tuple(data.get("element_names", np.array([])).tolist()),
               constraint_names=tuple(data.get("constraint_names", np.array([])).tolist()))


def table(traj):
    """(column names, (S, columns) data): t, coordinates, velocities (name_dot), energy,
    newton_iters, then the saved fields (width w > 1 as name_0..name_w-1; multipliers as
    lam_0..lam_m-1)."""
    header = ["t", *traj.coords, *(f"{c}_dot" for c in traj.coords), "energy", "newton_iters"]
    columns = [traj.t[:, None], traj.q, traj.v, traj.energy[:, None], traj.newton_iters[:, None]]
    short = {"multipliers": "lam"}
    for name, values in traj.saved.items():
        stem = short.get(name, name)
        header += [stem] if values.shape[1] == 1 and name not in short else [
            f"{stem}_{i}" for i in range(values.shape[1])]
        columns.append(values)
    return header, np.hstack(columns)


def write_csv(traj, path):
    header, data = table(traj)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    np.savetxt(path, data, delimiter=",", header=",".join(header), comments="", fmt="%.17g")


def dataframe(traj):
    """pandas.DataFrame of :func:`table`, indexed by t."""
    try:
        import pandas as pd
    except ImportError:
        raise LagrangeGenError("Trajectory.to_dataframe needs pandas: pip install "
                               "'lagrange-gen[dataframe]'") from None
    header, data = table(traj)
    index = pd.Index(data[:, 0], name="t")
    return pd.DataFrame(data[:, 1:], index=index, columns=header[1:])
