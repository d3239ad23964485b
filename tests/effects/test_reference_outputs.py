"""Bit for bit what the model gave before its numerics became one pathway (issue 32).

``tests/fixtures/physics/reference.npz`` holds the outputs of the code before the
refactor (two kernels, the baseline's and the effects'), written by
``make_reference.py`` beside it: every entry point, for the baseline and each effect. The
one compiled model of today, composed for no terms or for the union, must give exactly
those numbers — the baseline's arithmetic is unchanged, operation for operation.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from sim.config import StandConfig
from sim.effects import EFFECTS, EffectSpec, register, unregister
from sim.model import Model
from tests.effects import weight_viscous_damping
from tests.fixtures.physics.make_reference import CASES, drive, outputs

REFERENCE = Path(__file__).parent.parent / "fixtures" / "physics" / "reference.npz"
ADDED = "weight_viscous_damping"


@pytest.fixture(scope="module")
def reference() -> Iterator[dict[str, np.ndarray]]:
    with np.load(REFERENCE) as data:
        yield {key: data[key] for key in data.files}


@pytest.fixture(scope="module")
def added(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("LABSTAND_KERNEL_CACHE", str(tmp_path_factory.mktemp("kernels")))
        register(weight_viscous_damping.INFO)
        try:
            yield
        finally:
            unregister(ADDED)


def _check(reference: dict[str, np.ndarray], prefix: str, model: Model) -> None:
    got = outputs(model, reference["x"])
    keys = sorted(k for k in reference if k.startswith(prefix))
    assert sorted(prefix + k for k in got) == keys
    for key in keys:
        want, have = reference[key], got[key.removeprefix(prefix)]
        assert want.shape == have.shape, key
        # Exactly: the same operations in the same order give the same bits.
        assert np.array_equal(want, have), f"{key}: off by {np.abs(want - have).max():g}"


def test_the_drive_is_the_references(reference: dict[str, np.ndarray]) -> None:
    assert np.array_equal(reference["x"], drive())


@pytest.mark.parametrize("mass", [3.096, 8.131])
def test_the_baseline_is_bit_for_bit_the_old_baselines(
    stand: StandConfig, reference: dict[str, np.ndarray], mass: float
) -> None:
    _check(reference, f"baseline/{mass}/", Model(stand.stand_params("final", mass)))


@pytest.mark.parametrize("case", [c for c in CASES if c != "baseline"])
def test_each_effect_is_bit_for_bit_the_old_kernels(
    stand: StandConfig, reference: dict[str, np.ndarray], case: str
) -> None:
    _check(reference, f"{case}/8.131/", Model(stand.stand_params("final", 8.131), CASES[case]))


@pytest.mark.usefixtures("added")
def test_an_added_effect_is_bit_for_bit_the_old_composed_kernels(
    stand: StandConfig, reference: dict[str, np.ndarray]
) -> None:
    assert ADDED in EFFECTS
    model = Model(stand.stand_params("final", 8.131), [EffectSpec(ADDED)])
    _check(reference, f"{ADDED}/8.131/", model)
