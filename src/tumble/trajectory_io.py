"""Trajectory files: the ``.npz`` and HDF5 layouts, shared by :class:`~tumble.Trajectory` and the recorder.

Both formats hold the same named arrays (``docs/files.md``):

- per frame, first axis ``T``: ``time``, ``position``, ``orientation``, ``velocity``, ``angular_velocity``,
  ``kinetic_energy``, ``potential_energy``;
- per body: ``body_mass``, ``body_inertia``, ``body_com_local``, ``body_names``; and ``gravity``;
- ``metadata``: one JSON object (tumble version, dt, integrator, solver settings, scene, run status).

``.npz`` is one zip written at once (rewritten whole by the recorder at each chunk, through a temporary file and
an atomic rename, so a reader never sees half a file). HDF5 datasets grow along ``T`` and are flushed chunk by
chunk; h5py is imported only when an HDF5 file is read or written.
"""

from __future__ import annotations

import json
import os
import zipfile
from pathlib import Path

import numpy as np

__all__ = [
    "FRAME_ARRAYS",
    "STATIC_ARRAYS",
    "H5Frames",
    "is_hdf5_path",
    "read",
    "read_h5_metadata",
    "update_h5_metadata",
    "write_npz",
]

FRAME_ARRAYS = (
    "time", "position", "orientation", "velocity", "angular_velocity", "kinetic_energy", "potential_energy",
)  # fmt: skip
STATIC_ARRAYS = ("body_mass", "body_inertia", "body_com_local", "gravity")
# Trailing shape of each frame array for N bodies (None stands for N).
_FRAME_SHAPES = {
    "time": (), "position": (None, 3), "orientation": (None, 4), "velocity": (None, 3),
    "angular_velocity": (None, 3), "kinetic_energy": (), "potential_energy": (),
}  # fmt: skip
FORMAT_NAME = "tumble.trajectory"
FORMAT_VERSION = 1
_HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
_HDF5_SUFFIXES = (".h5", ".hdf5", ".he5")


def is_hdf5_path(path: str | os.PathLike) -> bool:
    """Whether ``path`` names an HDF5 file by its suffix (``.h5``, ``.hdf5``, ``.he5``)."""
    return Path(path).suffix.lower() in _HDF5_SUFFIXES


def _json_default(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"metadata values must be JSON-serialisable, got {value!r} ({type(value).__name__})")


def metadata_to_json(metadata: dict) -> str:
    return json.dumps(metadata, default=_json_default, sort_keys=True)


def _h5py():
    try:
        import h5py
    except ImportError as error:  # pragma: no cover - h5py is a dependency; kept for a clear message
        raise ImportError("HDF5 trajectories need h5py: pip install h5py") from error
    return h5py


# --- npz ----------------------------------------------------------------------------------------------------


_CHANNEL = "channel:"  # the .npz key prefix of a channel; in HDF5 the group "channels"


def write_npz(path: str | os.PathLike, arrays: dict, body_names: list[str], metadata: dict, *, compress=True,
              channels: dict | None = None) -> None:  # fmt: skip
    """Write every array of :data:`FRAME_ARRAYS` and :data:`STATIC_ARRAYS` to ``path`` atomically.

    The file goes to ``path`` exactly (numpy's ``savez`` would add ``.npz`` to a name without it); it is written
    next to ``path`` first and renamed over it, so a crash leaves the previous version whole.
    """
    path = Path(path)
    temporary = path.with_name(f".{path.name}.partial")
    save = np.savez_compressed if compress else np.savez
    with open(temporary, "wb") as f:
        save(
            f,
            **{k: arrays[k] for k in FRAME_ARRAYS + STATIC_ARRAYS},
            body_names=np.array(body_names, dtype=str).reshape(-1),
            metadata_json=np.array(metadata_to_json(metadata)),
            **{f"{_CHANNEL}{name}": np.asarray(value, dtype=np.float64) for name, value in (channels or {}).items()},
        )
        f.flush()
        os.fsync(f.fileno())
    os.replace(temporary, path)


def _read_npz(path) -> tuple[dict, list[str], dict]:
    with np.load(path, allow_pickle=False) as data:
        missing = [k for k in FRAME_ARRAYS + STATIC_ARRAYS if k not in data]
        if missing:
            raise ValueError(f"{os.fspath(path)!r} is not a tumble trajectory: missing arrays {missing}")
        arrays = {k: data[k] for k in FRAME_ARRAYS + STATIC_ARRAYS}
        arrays["channels"] = {k[len(_CHANNEL) :]: data[k] for k in data.files if k.startswith(_CHANNEL)}
        names = [str(n) for n in data["body_names"]] if "body_names" in data else []
        if "metadata_json" in data:
            metadata = json.loads(str(data["metadata_json"]))
        elif "metadata_keys" in data:  # files of tumble <= 0.1.0: string keys and values
            metadata = dict(zip(map(str, data["metadata_keys"]), map(str, data["metadata_values"]), strict=True))
            if "dt" in metadata:
                metadata["dt"] = float(metadata["dt"])
        else:
            metadata = {}
    return arrays, names, metadata


# --- HDF5 ---------------------------------------------------------------------------------------------------


class H5Frames:
    """An HDF5 trajectory file open for appending frames; each :meth:`append` is flushed to disk.

    Datasets are created with an unlimited first axis and grown by each append; the file is consistent on disk
    after every append, so a run killed later still leaves a readable file with every appended frame.

    Args:
        path: the file (overwritten).
        static: the arrays of :data:`STATIC_ARRAYS`.
        body_names: N names.
        metadata: JSON-serialisable dict, stored as the root attribute ``metadata``.
        chunk_frames: frames per HDF5 storage chunk along ``T`` (capped so that a chunk stays near 1 MiB).
        compression: None, ``"gzip"`` or ``"lzf"`` (h5py's filters).
    """

    def __init__(self, path, static: dict, body_names: list[str], metadata: dict, *, chunk_frames: int = 64,
                 compression: str | None = None) -> None:  # fmt: skip
        h5py = _h5py()
        body_count = int(static["body_mass"].shape[0])
        self._metadata_text: str | None = None  # what the file's metadata attribute holds
        self._file = h5py.File(path, "w")
        try:
            self._file.attrs["format"] = FORMAT_NAME
            self._file.attrs["format_version"] = FORMAT_VERSION
            for name in STATIC_ARRAYS:
                self._file.create_dataset(name, data=np.asarray(static[name], dtype=np.float64))
            self._file.create_dataset("body_names", data=list(body_names), dtype=h5py.string_dtype())
            for name, trailing in _FRAME_SHAPES.items():
                shape = tuple(body_count if n is None else n for n in trailing)
                row_bytes = 8 * max(1, int(np.prod(shape)))
                chunk = max(1, min(int(chunk_frames), (1 << 20) // row_bytes))
                self._file.create_dataset(
                    name, shape=(0, *shape), maxshape=(None, *shape), chunks=(chunk, *shape) if all(shape) else True,
                    dtype=np.float64, compression=compression,
                )  # fmt: skip
            self.set_metadata(metadata)
            self._file.flush()
        except BaseException:
            self._file.close()
            raise

    @property
    def frame_count(self) -> int:
        return int(self._file["time"].shape[0])

    def append(self, frames: dict) -> None:
        """Append the frames of the arrays of :data:`FRAME_ARRAYS` (same leading length) and flush."""
        count = int(np.shape(frames["time"])[0])
        if count:
            start = self.frame_count
            for name in FRAME_ARRAYS:
                dataset = self._file[name]
                dataset.resize(start + count, axis=0)
                dataset[start:] = frames[name]
        self._file.flush()

    def write_channels(self, channels: dict) -> None:
        """Store the per-frame ``channels`` (name: (T, ...) array), replacing any stored before, and flush."""
        group = self._file.require_group("channels")
        for name, value in channels.items():
            if name in group:
                del group[name]
            group.create_dataset(name, data=np.asarray(value, dtype=np.float64))
        self._file.flush()

    def set_metadata(self, metadata: dict) -> None:
        """Store ``metadata`` unless it is what the file holds already: HDF5 does not reuse an attribute's old
        space, so rewriting an unchanged scene at every chunk made a flagship run's file 40 % larger."""
        text = metadata_to_json(metadata)
        if text != self._metadata_text:
            self._file.attrs["metadata"] = text
            self._metadata_text = text

    def flush(self) -> None:
        self._file.flush()

    def close(self) -> None:
        if self._file.id.valid:
            self._file.close()


def write_h5(path, arrays: dict, body_names: list[str], metadata: dict, *, compression: str | None = "gzip",
             channels: dict | None = None) -> None:  # fmt: skip
    """Write a whole trajectory to an HDF5 file at once."""
    static = {k: arrays[k] for k in STATIC_ARRAYS}
    out = H5Frames(path, static, body_names, metadata, chunk_frames=256, compression=compression)
    try:
        out.append({k: arrays[k] for k in FRAME_ARRAYS})
        if channels:
            out.write_channels(channels)
    finally:
        out.close()


def _read_h5(path) -> tuple[dict, list[str], dict]:
    h5py = _h5py()
    with h5py.File(path, "r") as f:
        missing = [k for k in FRAME_ARRAYS + STATIC_ARRAYS if k not in f]
        if missing or f.attrs.get("format") != FORMAT_NAME:
            raise ValueError(f"{os.fspath(path)!r} is not a tumble trajectory: missing arrays {missing}")
        arrays = {k: f[k][()] for k in FRAME_ARRAYS + STATIC_ARRAYS}
        channels = {}
        if "channels" in f:
            f["channels"].visititems(
                lambda name, item: channels.update({name: item[()]}) if hasattr(item, "shape") else None
            )
        names = [n.decode() if isinstance(n, bytes) else str(n) for n in f["body_names"][()]]
        metadata = json.loads(f.attrs.get("metadata", "{}"))
    # Frames are appended array by array: a file cut off between two of them has one array longer; keep the
    # frames every array holds.
    count = min(arrays[k].shape[0] for k in FRAME_ARRAYS)
    for k in FRAME_ARRAYS:
        arrays[k] = arrays[k][:count]
    arrays["channels"] = {name: value[:count] for name, value in channels.items()}
    return arrays, names, metadata


def read_h5_metadata(path) -> dict:
    """The metadata of the HDF5 trajectory file at ``path`` alone (no frames read)."""
    with _h5py().File(path, "r") as f:
        if f.attrs.get("format") != FORMAT_NAME:
            raise ValueError(f"{os.fspath(path)!r} is not a tumble trajectory")
        return json.loads(f.attrs.get("metadata", "{}"))


def update_h5_metadata(path, entries: dict) -> None:
    """Add ``entries`` to the metadata of the (closed) HDF5 trajectory file at ``path``."""
    with _h5py().File(path, "r+") as f:
        metadata = json.loads(f.attrs.get("metadata", "{}"))
        metadata.update(entries)
        f.attrs["metadata"] = metadata_to_json(metadata)


def read(path: str | os.PathLike) -> tuple[dict, list[str], dict]:
    """``(arrays, body_names, metadata)`` from an ``.npz`` or HDF5 file (told apart by their first bytes).

    Raises:
        FileNotFoundError: no file at ``path``.
        ValueError: the file is not a tumble trajectory, or a damaged one (cut short, an array of the wrong shape or
            type, metadata that is not a JSON object); one message names the file and what is wrong, and nothing is
            returned half-read.
    """
    source = os.fspath(path)
    try:
        with open(path, "rb") as f:
            head = f.read(len(_HDF5_SIGNATURE))
    except FileNotFoundError:
        raise FileNotFoundError(f"no trajectory file at {source!r}") from None
    try:
        arrays, names, metadata = _read_h5(path) if head == _HDF5_SIGNATURE else _read_npz(path)
    except (FileNotFoundError, PermissionError, IsADirectoryError):
        raise
    except (OSError, EOFError, ValueError, KeyError, TypeError, UnicodeError, zipfile.BadZipFile) as error:
        if isinstance(error, ValueError) and str(error).startswith(repr(source)):
            raise  # already says which file and what
        raise ValueError(f"{source!r} is not a readable tumble trajectory: {_reason(error)}") from None
    problems = _problems(arrays, names, metadata)
    if problems:
        raise ValueError(f"{source!r} is not a valid tumble trajectory: " + "; ".join(problems))
    return arrays, names, metadata


def _reason(error: BaseException) -> str:
    text = str(error)
    if "pickled data" in text or "allow_pickle" in text:  # numpy's words for a file it does not know, or objects
        return "not an .npz or HDF5 file of numbers (tumble never reads pickled Python objects)"
    if isinstance(error, (EOFError, zipfile.BadZipFile)):
        return f"the file is cut short or damaged ({type(error).__name__}: {text})"
    return f"{type(error).__name__}: {text}" if text else type(error).__name__


def _problems(arrays: dict, names: list[str], metadata) -> list[str]:
    """What is wrong with the arrays read from a file: shapes that disagree, types that are not numbers."""
    problems = []
    for key in FRAME_ARRAYS + STATIC_ARRAYS:
        if arrays[key].dtype.kind not in "fiu":
            problems.append(f"{key} holds {arrays[key].dtype} values, not numbers")
    if problems:
        return problems
    frames, bodies = arrays["time"].shape[0] if arrays["time"].ndim == 1 else -1, arrays["body_mass"].shape[0]
    expected = {key: (frames, *(bodies if n is None else n for n in trailing)) for key, trailing in
                _FRAME_SHAPES.items()}  # fmt: skip
    expected.update(body_mass=(bodies,), body_inertia=(bodies, 3, 3), body_com_local=(bodies, 3), gravity=(3,))
    for key, shape in expected.items():
        if arrays[key].shape != shape:
            problems.append(f"{key} has shape {arrays[key].shape}, expected {shape}")
    if names and len(names) != bodies:
        problems.append(f"{len(names)} body names for {bodies} bodies")
    for name, channel in arrays.get("channels", {}).items():
        # A run that failed before the channels' first sample holds fewer of them than frames, never more.
        if channel.dtype.kind not in "fiu" or channel.ndim < 1 or channel.shape[0] > frames:
            problems.append(f"channel {name!r} is {channel.shape} {channel.dtype}, expected {frames} frames of numbers")
    if not isinstance(metadata, dict):
        problems.append(f"metadata is a JSON {type(metadata).__name__}, not an object")
    return problems
