"""Real-like recordings: gauge noise, mains hum, quantisation, and mismatched stands."""

from __future__ import annotations

import numpy as np
import pytest

from sim.config import StandConfig
from sim.effects import (
    MeasurementNoise,
    NoiseSpec,
    add_measurement_noise,
    draw_real_stand,
)
from sim.model import Model
from tests.effects.helpers import RATE, situation_drive


def test_noise_levels_hum_and_quantisation(stand: StandConfig) -> None:
    p = stand.stand_params("final")
    truth = Model(p).run(np.zeros(40_000), RATE)  # 20 s at rest
    spec = NoiseSpec(force_rms_n=0.1, displacement_rms_m=5e-6, hum_force_n=0.05)
    rec = add_measurement_noise(truth, np.random.default_rng(1), spec)
    du, df = rec.u_m - truth.u_m, rec.force_n - truth.force_n
    # Counts: every reading is a whole number of LSBs.
    assert np.allclose(rec.force_n / 1e-3, np.round(rec.force_n / 1e-3), atol=1e-6)
    assert np.allclose(rec.u_m / 1e-7, np.round(rec.u_m / 1e-7), atol=1e-6)
    hum_u = spec.hum_displacement_m**2 / 2
    assert np.std(du) == pytest.approx(np.sqrt(5e-6**2 + hum_u + 1e-7**2 / 12), rel=0.03)
    assert np.std(df) == pytest.approx(np.sqrt(0.1**2 + 0.05**2 / 2 + 1e-6 / 12), rel=0.03)
    # The hum is a 50 Hz line of the stated amplitude.
    spectrum = np.abs(np.fft.rfft(df)) * 2 / df.size
    freq = np.fft.rfftfreq(df.size, 1 / RATE)
    assert freq[np.argmax(spectrum)] == pytest.approx(50.0)
    assert spectrum.max() == pytest.approx(0.05, rel=0.1)
    assert np.array_equal(rec.x_m, truth.x_m)


def test_noise_is_seeded_and_block_invariant(stand: StandConfig) -> None:
    x, mass = situation_drive(stand, "11")
    truth = Model(stand.stand_params("final", mass)).run(x, RATE)
    one = add_measurement_noise(truth, np.random.default_rng(9))
    again = add_measurement_noise(truth, np.random.default_rng(9))
    assert np.array_equal(one.force_n, again.force_n) and np.array_equal(one.u_m, again.u_m)
    noise = MeasurementNoise(NoiseSpec(), RATE, np.random.default_rng(9))
    blocks = zip(np.array_split(truth.u_m, 7), np.array_split(truth.force_n, 7), strict=True)
    parts = [noise.apply(u, f) for u, f in blocks]
    assert np.array_equal(np.concatenate([u for u, _ in parts]), one.u_m)
    assert np.array_equal(np.concatenate([f for _, f in parts]), one.force_n)


def test_drawn_noise_levels_are_real_like() -> None:
    rng = np.random.default_rng(3)
    for _ in range(50):
        spec = NoiseSpec.draw(rng)
        assert 0.05 <= spec.force_rms_n <= 0.2
        assert 2e-6 <= spec.displacement_rms_m <= 10e-6
        assert spec.hum_force_n <= spec.force_rms_n


def test_real_stands_differ_from_nominal_within_the_spread(stand: StandConfig) -> None:
    nominal = stand.stand_params("final")
    draws = [draw_real_stand(nominal, np.random.default_rng(s)) for s in range(200)]
    for attr in ("stiffness_n_m", "damping_n_s_m", "friction_scale"):
        ratio = np.array([getattr(d, attr) / getattr(nominal, attr) for d in draws])
        assert ratio.min() >= 0.75 and ratio.max() <= 1.25
        assert ratio.min() < 0.8 and ratio.max() > 1.2  # the spread is used
    assert draw_real_stand(nominal, np.random.default_rng(4)) == draw_real_stand(
        nominal, np.random.default_rng(4)
    )
    assert draws[0].mass_kg == nominal.mass_kg  # geometry and mass stay nominal
    with pytest.raises(ValueError, match="spread"):
        draw_real_stand(nominal, np.random.default_rng(0), spread=1.5)
