"""The parameter table, pinned against HARDWARE.md (addresses copied from that page)."""

from __future__ import annotations

import pytest

from drivers import unidrive_registers as pr
from drivers.signals import Shape, SignalSpec
from drivers.unidrive_profile import ShapeCode, decode_profile, encode_home, encode_profile
from drivers.unidrive_registers import ADDRESS_32BIT, ControlBit, StatusBit

# HARDWARE.md, "Parameters an application uses": Pr → 16-bit address, as printed there.
HARDWARE_MD = {
    (1, 14): 113,
    (1, 21): 120,
    (6, 4): 603,
    (6, 15): 614,
    (6, 42): 641,
    (6, 43): 642,
    (10, 1): 1000,
    (10, 20): 1019,
    (10, 38): 1037,
    (10, 40): 1039,
    (11, 23): 1122,
    (11, 24): 1123,
    (11, 25): 1124,
    (11, 26): 1125,
}


# HARDWARE.md prints "3.02 [201]" and "3.28 / 3.29 / 3.30 [227–229]", which contradicts
# its own [manual] rule menu*100 + param − 1 (201 is Pr 2.02). The rule wins; the page's
# menu-3 rows are reported as an erratum (docs/hardware-design.md).
HARDWARE_MD_ERRATA = {
    (3, 2): (201, 301),
    (3, 28): (227, 327),
    (3, 29): (228, 328),
    (3, 30): (229, 329),
}


@pytest.mark.parametrize(("pr_", "printed_and_rule"), sorted(HARDWARE_MD_ERRATA.items()))
def test_menu3_rows_follow_the_rule_not_the_misprint(
    pr_: tuple[int, int], printed_and_rule: tuple[int, int]
) -> None:
    printed, rule = printed_and_rule
    reg = pr.by_parameter(*pr_)
    assert reg.address16 == rule == pr_[0] * 100 + pr_[1] - 1
    assert printed != rule
    assert pr.by_address(printed) is not reg


@pytest.mark.parametrize(("pr_", "address"), sorted(HARDWARE_MD.items()))
def test_addresses_match_hardware_md(pr_: tuple[int, int], address: int) -> None:
    assert pr.by_parameter(*pr_).address16 == address


def test_32bit_addresses_match_hardware_md() -> None:
    # "For 32-bit access set bit 14 of the address (0x4000 | addr, Pr 1.21 → 16504)"
    assert pr.SPEED_REFERENCE.address == 16504
    assert pr.SPEED_REFERENCE.count == 2
    assert pr.TRIP_CODE.address == 1019 and pr.TRIP_CODE.count == 1
    assert pr.CONTROL_WORD.address == 641


def test_every_register_follows_the_addressing_rule() -> None:
    seen = set()
    for reg in pr.REGISTERS:
        assert reg.address16 == reg.menu * 100 + reg.param - 1
        expected = reg.address16 | ADDRESS_32BIT if reg.width == 32 else reg.address16
        assert reg.address == expected
        assert reg.address16 not in seen
        seen.add(reg.address16)
        assert pr.by_address(reg.address) is reg
        assert reg.label.startswith(f"Pr {reg.menu}.{reg.param:02d} (")


def test_drive_program_uses_application_menus_only() -> None:
    program = {*pr.PROFILE_BLOCK, *pr.STATUS_BLOCK, *pr.LIMIT_BLOCK, pr.REJECT_REASON}
    assert all(18 <= r.menu <= 20 for r in program)
    # the profile is written, and the status block read, in one request of ≤ 16 registers
    for block in (pr.PROFILE_BLOCK, pr.STATUS_BLOCK):
        assert sum(r.count for r in block) <= pr.MAX_REGISTERS
        assert [r.param for r in block] == list(range(block[0].param, block[0].param + len(block)))
        assert {r.width for r in block} == {32}


def test_unknown_parameter_is_refused_by_name() -> None:
    assert pr.by_address(5 * 100 + 1 - 1) is None
    with pytest.raises(KeyError, match=r"Pr 5\.01"):
        pr.by_parameter(5, 1)


def test_control_words_of_hardware_md() -> None:
    # "Common words: 128 disabled, 129 enabled, 131 enabled and running forward."
    auto, enable, run_fwd = ControlBit.AUTO.mask, ControlBit.ENABLE.mask, ControlBit.RUN_FWD.mask
    assert auto == 128
    assert auto | enable == 129
    assert auto | enable | run_fwd == 131
    assert ControlBit.WATCHDOG.mask == 1 << 14
    assert ControlBit.TRIP.value == 12 and ControlBit.RESET.value == 13
    assert ControlBit.REMOTE.value == 8


def test_status_bits_of_hardware_md() -> None:
    assert [StatusBit.HEALTHY, StatusBit.ACTIVE, StatusBit.ZERO_SPEED, StatusBit.AT_SPEED] == [
        0,
        1,
        2,
        5,
    ]
    assert StatusBit.MAINS_LOSS == 14


def test_scaling_round_trip() -> None:
    assert pr.PROFILE_AMPLITUDE.to_raw(0.0305) == 30500  # µm
    assert pr.PROFILE_AMPLITUDE.to_value(30500) == pytest.approx(0.0305)
    assert pr.SPEED_REFERENCE.to_raw(1500.0) == 15000  # 0.1 rpm


def test_profile_round_trip_quantises_once() -> None:
    spec = SignalSpec(Shape.TRAPEZOIDAL, 0.0301234567, 1.2345678, 3, 0.2, 0.5, 1.0)
    raws = encode_profile(spec)
    assert raws[0] == ShapeCode.TRAPEZOIDAL
    back = decode_profile(raws)
    assert back.shape is Shape.TRAPEZOIDAL
    assert back.amplitude_m == pytest.approx(spec.amplitude_m, abs=0.5e-6)
    assert back.frequency_hz == pytest.approx(spec.frequency_hz, abs=0.5e-6)
    assert (back.cycles, back.ramp_fraction, back.dwell_start_s) == (3, 0.2, 0.5)
    assert encode_profile(back) == raws  # decoding is exact: both sides plan the same motion


def test_home_and_bad_shapes_are_not_signals() -> None:
    assert encode_home()[0] == ShapeCode.HOME
    with pytest.raises(ValueError, match="not a signal shape"):
        decode_profile(encode_home())
    with pytest.raises(ValueError, match="parameters"):
        decode_profile([1, 2])
