"""Ensembles and sweeps: many independent runs of a world, one per set of parameters, on every core or on a Dask
cluster (see ``docs/ensembles.md``).

>>> from tumble import ensemble
>>> members = ensemble.grid({"bodies[0].friction": [0.1, 0.5], "world.gravity[2]": [-9.81, -1.62]})
>>> len(members), members[1]
(4, {'bodies[0].friction': 0.1, 'world.gravity[2]': -1.62})

``ensemble.run("ramp.toml", members, out_dir="out/ramp")`` then runs the four on a local process pool (workers
are started fresh, so a script calling it needs the usual ``if __name__ == "__main__":``), writes one trajectory
per member and returns the table of results; calling it again runs only the members without a finished file.
"""

from __future__ import annotations

from .params import grid, sample
from .runner import RESULTS_FILE, run

__all__ = ["run", "grid", "sample", "RESULTS_FILE"]
