"""Loading MJCF models: tumble's reader and builder beside MuJoCo's compiler, in the same process (issue 25).

Run from the repository root:

    python -m benchmarks.run --only model_files

Models: Gymnasium's humanoid (13 bodies, 21 degrees of freedom, default classes, capsules from ``fromto``), a
generated chain of ``chain_links`` (100) capsule links hinged about y, one nested in the other, and dm_control's dog
(62 bodies, 85 degrees of freedom, 162 STL bone meshes weighed in MuJoCo's legacy mode, ``springdamper`` joints).
Rows: tumble's ``read_mjcf`` (the XML into the plain description: parse, defaults, inertia from the geoms),
``from_mjcf`` (that and the articulation), ``from_mjcf`` and a first mass matrix (the articulation packed for its
kernels; the kernels are loaded from Numba's cache before timing), and MuJoCo's ``MjModel.from_xml_path`` (parse and
compile). Columns: ``ms`` (best of ``repeat`` loads) and ``x_mujoco`` (tumble's time over MuJoCo's: below 1 is
faster).
"""

from __future__ import annotations

import os
import time
import warnings
from pathlib import Path

__all__ = ["bench_mjcf_contacts", "bench_model_files", "chain_mjcf", "dog_path", "humanoid_path"]


def humanoid_path() -> str | None:
    """Gymnasium's humanoid.xml, or None without Gymnasium."""
    try:
        import gymnasium
    except ImportError:
        return None
    return os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets", "humanoid.xml")


def dog_path() -> str | None:
    """dm_control's dog.xml, found without importing dm_control (which opens a window system), or None."""
    import importlib.util

    spec = importlib.util.find_spec("dm_control")
    return None if spec is None else os.path.join(os.path.dirname(spec.origin), "suite", "dog.xml")


def chain_mjcf(links: int) -> str:
    """A chain of ``links`` capsules of 0.1 m along x, each hinged about y at its parent's tip, nested bodies."""
    body = ""
    for i in reversed(range(links)):
        pos = "0 0 1" if i == 0 else "0.1 0 0"
        body = (f'<body name="link{i}" pos="{pos}"><joint name="hinge{i}" axis="0 1 0" damping="0.01"/>'
                f'<geom type="capsule" fromto="0 0 0 0.1 0 0" size="0.01"/>{body}</body>')  # fmt: skip
    return f'<mujoco model="chain"><option timestep="0.001"/><worldbody>{body}</worldbody></mujoco>'


def _best(run, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        run()
        best = min(best, time.perf_counter() - start)
    return best


def bench_model_files(chain_links: int = 100, repeat: int = 5) -> list[dict]:
    """One row per model and loader; ``x_mujoco`` against MuJoCo's compiler on the same file."""
    from tumble.articulation import from_mjcf
    from tumble.models.mjcf import MJCFWarning, read_mjcf

    rows = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MJCFWarning)
        chain_file = Path(os.environ.get("TMPDIR", "/tmp")) / f"tumble_bench_chain_{chain_links}.xml"
        chain_file.write_text(chain_mjcf(chain_links))
        models = [("humanoid", humanoid_path()), (f"chain of {chain_links}", str(chain_file)), ("dog", dog_path())]
        from_mjcf(str(chain_file)).mass_matrix()  # load the articulation kernels before timing
        for name, path in models:
            if path is None:
                continue
            loaders = {
                "tumble read_mjcf": lambda p=path: read_mjcf(p),
                "tumble from_mjcf": lambda p=path: from_mjcf(p),
                "tumble from_mjcf + mass_matrix": lambda p=path: from_mjcf(p).mass_matrix(),
            }
            try:
                import mujoco

                loaders["MuJoCo MjModel.from_xml_path"] = lambda p=path: mujoco.MjModel.from_xml_path(p)
            except ImportError:
                pass
            times = {loader: _best(run, repeat) for loader, run in loaders.items()}
            reference = times.get("MuJoCo MjModel.from_xml_path")
            for loader, seconds in times.items():
                row = {"model": name, "loader": loader, "ms": 1e3 * seconds}
                if reference is not None:
                    row["x_mujoco"] = seconds / reference
                rows.append(row)
        chain_file.unlink()
    return rows


def bench_mjcf_contacts(seconds: float = 5.0, repeat: int = 3) -> list[dict]:
    """Gymnasium's ant and humanoid with contacts, in a tumble World (``tumble.load_mjcf``) and in MuJoCo, each at its
    model's timestep (0.01 s and 0.003 s): dropped from its pose, their motors (8 and 17) held at the same controls
    in both engines. Rows per model and engine:
    ``steps_per_s`` (best of ``repeat`` runs of ``seconds`` simulated), ``realtime`` (simulated over wall-clock
    seconds) and ``x_mujoco`` (MuJoCo's time over tumble's: above 1 tumble is faster)."""
    import numpy as np

    import tumble

    path = humanoid_path()
    if path is None:
        return []
    folder = os.path.dirname(path)
    rows = []
    for name, ctrl in (("ant", np.sin(np.arange(8) * 1.7)), ("humanoid", 0.4 * np.sin(np.arange(17) * 1.7))):
        model_path = os.path.join(folder, f"{name}.xml")
        runs = {"tumble World": _tumble_world_run(tumble, model_path, ctrl, seconds)}
        try:
            import mujoco

            runs["MuJoCo"] = _mujoco_run(mujoco, model_path, ctrl, seconds)
        except ImportError:
            pass
        times = {engine: min(run() for _ in range(repeat)) for engine, run in runs.items()}
        dt = _timestep(model_path)
        steps = round(seconds / dt)
        rows += [{"model": name, "dt": dt, "engine": engine, "steps_per_s": steps / wall, "realtime": seconds / wall,
                  **({"x_mujoco": times["MuJoCo"] / wall} if "MuJoCo" in times else {})}
                 for engine, wall in times.items()]  # fmt: skip
    return rows


def _timestep(path: str) -> float:
    from tumble.models.mjcf import read_mjcf

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return float(read_mjcf(path).timestep)


def _tumble_world_run(tumble, path: str, ctrl, seconds: float):
    dt = _timestep(path)

    def run() -> float:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            world = tumble.load_mjcf(path)
        if ctrl is not None:
            world.ctrl = ctrl
        world.step(dt)  # the kernels loaded before timing
        start = time.perf_counter()
        for _ in range(round(seconds / dt)):
            world.step(dt)
        return time.perf_counter() - start

    return run


def _mujoco_run(mujoco, path: str, ctrl, seconds: float):
    def run() -> float:
        model = mujoco.MjModel.from_xml_path(path)
        data = mujoco.MjData(model)
        if ctrl is not None:
            data.ctrl[:] = ctrl
        mujoco.mj_step(model, data)
        start = time.perf_counter()
        mujoco.mj_step(model, data, nstep=round(seconds / model.opt.timestep))
        return time.perf_counter() - start

    return run
