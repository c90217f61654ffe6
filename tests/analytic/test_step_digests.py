"""No result changes when the step's structure does (issue 45): every shipped scene at 60 and 240 Hz, each one of them
stepped from Python, a batch, an env rollout and an ensemble member end in the bits recorded in
``tests/data/step_digests.json`` (written by ``python tests/step_digests.py --write`` before the change).

The recorded bits are every machine's: the probe gives the same digests under OpenBLAS's Haswell and Sandybridge
kernels and Numba for a generic x86-64. A change that alters physics on purpose records them again, and says so.
"""

from __future__ import annotations

import json

import pytest

import step_digests
from compiled import compiled_only

RECORDED = json.loads(step_digests.DATA.read_text())

pytestmark = compiled_only("2 s of every shipped scene at two rates: minutes as plain Python")


def test_every_case_is_recorded():
    assert sorted(RECORDED) == sorted(step_digests.CASES)


@pytest.mark.parametrize("case", sorted(step_digests.CASES))
def test_the_same_bits_as_recorded(case):
    assert step_digests.digest(case) == RECORDED[case]
