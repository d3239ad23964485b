# Over 400 lines: the stand file validated key by key, each with its unit, range and message.
"""The stand configuration: a TOML file, validated key by key.

The embedded ``default_stand.toml`` is the paper's stand. A user's file overlays it: it
may change any key and add named parameter sets, friction tables and weights. Every
invalid value is a ConfigError whose one-line message names the file, the table and the
key (see docs/configuration.md for the keys, their units and ranges).
"""

from __future__ import annotations

import copy
import itertools
import math
import re
import tomllib
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

from drivers.calibration import GaugeCalibration
from drivers.limits import DriveLimits
from sim.envelope import StandEnvelope
from sim.params import FrictionTable, StandParams

__all__ = [
    "ConfigError",
    "DeviceConfig",
    "ParameterSet",
    "StandConfig",
    "default_config",
    "load_config",
]

#: The drive's mechanical stroke [paper]; a configured limit beyond it is refused.
STROKE_MAX_MM = 90.0
DEFAULT_SOURCE = "<default stand>"
#: Arrays, inline tables and dotted keys nested deeper than this are refused before parsing
#: (tomllib recurses once per level; the stand file's deepest key is 3 levels down).
MAX_NESTING = 16
#: A stand file is a few kB; one larger than this is refused before it is read (tomllib
#: holds the whole text and its tables in memory).
MAX_STAND_FILE_BYTES = 2**20
#: The fastest acquisition rate a stand file may ask for, Hz: the gauges stream at 2 kHz,
#: and the rate sizes every simulated and recorded array (1e12 asked for 29 TiB).
MAX_SAMPLE_RATE_HZ = 1e5


class ConfigError(ValueError):
    """A stand configuration that cannot be used; the message names file and key."""


@dataclass(frozen=True)
class ParameterSet:
    """A named set of fibre parameters and the friction table it uses."""

    name: str
    stiffness_n_m: float
    damping_n_s_m: float
    friction: str  # a [friction.NAME] table, or "none"


@dataclass(frozen=True)
class DeviceConfig:
    """Where the real stand's devices are: the optional ``[devices]`` table.

    A stand file without it describes no hardware, and ``labstand run`` uses the
    simulated stand.

    Attributes
    ----------
    drive
        The Unidrive SP: ``tcp://HOST[:PORT]`` (Modbus TCP) or
        ``rtu:///dev/ttyUSB1[?baudrate=115200&stopbits=2&parity=N]`` (Modbus RTU).
    gauges
        The gauge front end's serial port, e.g. ``/dev/ttyUSB0``.
    gauges_baudrate
        Its line speed, baud (2 kHz × 24-byte frames need ≥ 480 000).
    """

    drive: str
    gauges: str
    gauges_baudrate: int = 921_600


Check = Callable[[Any], str | None]  # returns a complaint, or None when the value is fine


def _show(value: Any) -> str:
    """``repr`` of a value, cut short: a message stays one readable line."""
    if isinstance(value, int) and value.bit_length() > 200:  # repr fails beyond 4300 digits
        return f"an integer of {value.bit_length()} bits"
    text = repr(value)
    return text if len(text) <= 60 else f"{text[:57]}..."


def _number(lo: float | None = None, hi: float | None = None, strict: bool = True) -> Check:
    def check(value: Any) -> str | None:
        if isinstance(value, bool) or not isinstance(value, int | float):
            return f"must be a number, got {type(value).__name__} {_show(value)}"
        if isinstance(value, int) and value.bit_length() > 1000:  # beyond float64: 2**1024
            return f"must be a number in range, got an integer of {value.bit_length()} bits"
        if not math.isfinite(value):
            return f"must be finite, got {value}"
        if lo is not None and (value <= lo if strict else value < lo):
            return f"must be {'>' if strict else '≥'} {lo:g}, got {value:g}"
        if hi is not None and value > hi:
            return f"must be ≤ {hi:g}, got {value:g}"
        return None

    return check


def _text(value: Any) -> str | None:
    return None if isinstance(value, str) else f"must be a string, got {_show(value)}"


def _number_list(value: Any) -> str | None:
    if not isinstance(value, list) or len(value) < 2:
        return f"must be a list of at least 2 numbers, got {_show(value)}"
    for item in value:
        if (msg := _number(0.0, strict=False)(item)) is not None:
            return f"every entry {msg}"
    return None


def _drive_url(value: Any) -> str | None:
    if not isinstance(value, str) or not value.startswith(("tcp://", "rtu://")):
        return f"must be a tcp://HOST:PORT or rtu://PATH URL, got {_show(value)}"
    return None


def _port(value: Any) -> str | None:
    if not isinstance(value, str) or not value.strip():
        return f"must be a serial port path, got {_show(value)}"
    return None


def _baudrate(value: Any) -> str | None:
    if isinstance(value, bool) or not isinstance(value, int) or value <= 0:
        return f"must be a positive whole number of baud, got {_show(value)}"
    return None


_DEVICE_KEYS: dict[str, Check] = {
    "drive": _drive_url,
    "gauges": _port,
    "gauges_baudrate": _baudrate,
}
POSITIVE = _number(0.0)
NON_NEGATIVE = _number(0.0, strict=False)
ANY_NUMBER = _number()

_FIXED_TABLES: dict[str, dict[str, Check]] = {
    "geometry": {
        "fibre_length_m": POSITIVE,
        "fibre_mass_kg": POSITIVE,
        "pulley_radius_m": POSITIVE,
        "wrap_angle_deg": _number(0.0, 360.0),
        "incline_deg": _number(0.0, 90.0, strict=False),
        "lateral_offset_m": NON_NEGATIVE,
        "free_length_m": POSITIVE,
        "gravity_m_s2": POSITIVE,
    },
    "weight": {"default": _text},
    "drive": {
        "amplitude_max_mm": _number(0.0, STROKE_MAX_MM),
        "speed_max_m_s": POSITIVE,
        "accel_max_m_s2": POSITIVE,
    },
    "safety": {"weight_travel_max_mm": POSITIVE, "fibre_tension_max_n": POSITIVE},
    "acquisition": {"sample_rate_hz": _number(0.0, MAX_SAMPLE_RATE_HZ)},
    "gauges": {
        "force_n_per_count": POSITIVE,
        "force_offset_n": ANY_NUMBER,
        "position_mm_per_count": POSITIVE,
        "position_offset_mm": ANY_NUMBER,
        "drive_mm_per_count": POSITIVE,
        "drive_offset_mm": ANY_NUMBER,
    },
}
_PARAM_SET_KEYS: dict[str, Check] = {
    "stiffness_n_m": POSITIVE,
    "damping_n_s_m": NON_NEGATIVE,
    "friction": _text,
}
_FRICTION_KEYS: dict[str, Check] = {
    "speed_m_s": _number_list,
    "mu": _number_list,
    "v_reg_m_s": POSITIVE,
}
_NAMED_TABLES = {"params": _PARAM_SET_KEYS, "friction": _FRICTION_KEYS}


@dataclass(frozen=True)
class StandConfig:
    """A validated stand configuration (see docs/configuration.md)."""

    geometry: Mapping[str, float]
    weights_kg: Mapping[str, float]
    default_weight: str
    parameter_sets: Mapping[str, ParameterSet]
    friction_tables: Mapping[str, FrictionTable]
    drive: DriveLimits
    #: What the stand survives: ``labstand run`` refuses a motion predicted beyond it.
    envelope: StandEnvelope
    sample_rate_hz: float
    gauges: GaugeCalibration
    source: str
    raw: Mapping[str, Any]
    devices: DeviceConfig | None = None

    @property
    def default_mass_kg(self) -> float:
        """Mass of the weight a run uses unless told otherwise, kg."""
        return self.weights_kg[self.default_weight]

    def stand_params(self, params: str = "final", mass_kg: float | None = None) -> StandParams:
        """The model's parameters for a named set and a weight mass (default weight if None)."""
        if params not in self.parameter_sets:
            known = ", ".join(sorted(self.parameter_sets))
            raise ConfigError(f"{self.source}: no parameter set {params!r}; known: {known}")
        mass = self.default_mass_kg if mass_kg is None else mass_kg
        if not (math.isfinite(mass) and mass > 0):
            raise ConfigError(f"mass must be > 0 kg, got {mass:g} kg")
        pset = self.parameter_sets[params]
        friction = None if pset.friction == "none" else self.friction_tables[pset.friction]
        return StandParams(
            mass_kg=mass,
            stiffness_n_m=pset.stiffness_n_m,
            damping_n_s_m=pset.damping_n_s_m,
            friction=friction,
            **self.geometry,
        )

    def to_dict(self) -> dict[str, Any]:
        """The configuration as plain TOML-able data (for recordings' metadata)."""
        return copy.deepcopy(dict(self.raw))


def _complain(source: str, table: str, key: str, msg: str) -> ConfigError:
    return ConfigError(f"{source}: [{table}] {key}: {msg}")


def _check_table(source: str, name: str, table: Any, checks: dict[str, Check]) -> None:
    if not isinstance(table, dict):
        raise ConfigError(f"{source}: [{name}] must be a table, got {_show(table)}")
    for key, value in table.items():
        if key not in checks:
            expected = ", ".join(sorted(checks))
            raise _complain(source, name, key, f"unknown key; expected one of {expected}")
        if (msg := checks[key](value)) is not None:
            raise _complain(source, name, key, msg)
    for key in checks:
        if key not in table:
            raise _complain(source, name, key, "missing")


def _merge(base: dict[str, Any], over: Mapping[str, Any]) -> dict[str, Any]:
    out = copy.deepcopy(base)
    for key, value in over.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = _merge(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out


def _friction_table(source: str, name: str, data: dict[str, Any]) -> FrictionTable:
    speeds, mus = data["speed_m_s"], data["mu"]
    where = f"friction.{name}"
    if len(speeds) != len(mus):
        raise _complain(source, where, "mu", f"needs {len(speeds)} values (one per speed)")
    if any(b <= a for a, b in itertools.pairwise(speeds)):
        raise _complain(source, where, "speed_m_s", f"must be strictly increasing, got {speeds}")
    if speeds[0] <= 0:
        raise _complain(source, where, "speed_m_s", f"must start above 0 m/s, got {speeds[0]}")
    return FrictionTable(
        tuple(map(float, speeds)), tuple(map(float, mus)), float(data["v_reg_m_s"])
    )


def config_from_dict(data: Mapping[str, Any], source: str = DEFAULT_SOURCE) -> StandConfig:
    """Validate an overlay on the defaults and build the configuration."""
    merged = _merge(_default_data(), data)
    allowed = set(_FIXED_TABLES) | set(_NAMED_TABLES) | {"weights_kg", "devices"}
    for key in merged:
        if key not in allowed:
            raise ConfigError(
                f"{source}: unknown table [{key}]; expected one of {', '.join(sorted(allowed))}"
            )
    for name, checks in _FIXED_TABLES.items():
        _check_table(source, name, merged[name], checks)
    tables: dict[str, dict[str, Any]] = {}
    for group, checks in _NAMED_TABLES.items():
        if not isinstance(merged[group], dict):
            raise ConfigError(f"{source}: [{group}] must be a table of named tables")
        for name, table in merged[group].items():
            _check_table(source, f"{group}.{name}", table, checks)
        tables[group] = merged[group]
    weights = merged["weights_kg"]
    named = {name: POSITIVE for name in weights} if isinstance(weights, dict) else {}
    _check_table(source, "weights_kg", weights, named)
    default_weight = merged["weight"]["default"]
    if default_weight not in weights:
        msg = f"names no weight in [weights_kg] ({', '.join(sorted(weights))}): {default_weight!r}"
        raise _complain(source, "weight", "default", msg)
    frictions = {n: _friction_table(source, n, t) for n, t in tables["friction"].items()}
    psets = {}
    for name, t in tables["params"].items():
        if t["friction"] != "none" and t["friction"] not in frictions:
            msg = f"names no [friction.*] table (or 'none'): {t['friction']!r}"
            raise _complain(source, f"params.{name}", "friction", msg)
        psets[name] = ParameterSet(
            name, float(t["stiffness_n_m"]), float(t["damping_n_s_m"]), t["friction"]
        )
    geometry = {k: float(v) for k, v in merged["geometry"].items()}
    if geometry["lateral_offset_m"] >= geometry["free_length_m"]:
        msg = "must be shorter than free_length_m (the fibre cannot reach the weight)"
        raise _complain(source, "geometry", "lateral_offset_m", msg)
    drive = merged["drive"]
    safety = merged["safety"]
    gauges = merged["gauges"]
    return StandConfig(
        geometry=geometry,
        weights_kg={k: float(v) for k, v in weights.items()},
        default_weight=default_weight,
        parameter_sets=psets,
        friction_tables=frictions,
        drive=DriveLimits(
            amplitude_max_m=drive["amplitude_max_mm"] / 1e3,
            speed_max_m_s=float(drive["speed_max_m_s"]),
            accel_max_m_s2=float(drive["accel_max_m_s2"]),
        ),
        envelope=StandEnvelope(
            weight_travel_max_m=safety["weight_travel_max_mm"] / 1e3,
            fibre_tension_max_n=float(safety["fibre_tension_max_n"]),
        ),
        sample_rate_hz=float(merged["acquisition"]["sample_rate_hz"]),
        gauges=GaugeCalibration(**{k: float(v) for k, v in gauges.items()}),
        source=source,
        raw=merged,
        devices=_devices(source, merged.get("devices")),
    )


def _devices(source: str, table: Any) -> DeviceConfig | None:
    """The optional [devices] table: drive and gauges required, gauges_baudrate optional."""
    if table is None:
        return None
    full = (
        {"gauges_baudrate": DeviceConfig.gauges_baudrate, **table}
        if isinstance(table, dict)
        else table
    )
    _check_table(source, "devices", full, _DEVICE_KEYS)
    return DeviceConfig(full["drive"], full["gauges"], full["gauges_baudrate"])


def _default_data() -> dict[str, Any]:
    text = resources.files("sim").joinpath("default_stand.toml").read_text(encoding="utf-8")
    return tomllib.loads(text)


def default_config() -> StandConfig:
    """The paper's stand."""
    return config_from_dict({})


def load_config(path: str | Path | None) -> StandConfig:
    """Load a stand file overlaid on the defaults; None gives the defaults."""
    if path is None:
        return default_config()
    p = Path(path)
    try:
        if (size := p.stat().st_size) > MAX_STAND_FILE_BYTES:
            raise ConfigError(
                f"{p}: {size} bytes, larger than a stand file can be ({MAX_STAND_FILE_BYTES} bytes)"
            )
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(f"{p}: no such stand file") from None
    except (OSError, UnicodeDecodeError) as err:
        raise ConfigError(f"{p}: cannot read stand file: {err}") from None
    if (where := _too_deep_text(text)) is not None:
        raise ConfigError(f"{p}: {where}: arrays or tables nested deeper than {MAX_NESTING} levels")
    try:
        data = tomllib.loads(text)
    except ValueError as err:  # TOMLDecodeError, or int() of more than 4300 digits
        raise ConfigError(f"{p}: not valid TOML: {err}") from None
    if (key := _too_deep_data(data)) is not None:
        raise ConfigError(f"{p}: key {key}: tables nested deeper than {MAX_NESTING} levels")
    return config_from_dict(data, str(p))


_TOKENS = re.compile(r"[\[\]{}\"'#\n=]|(?<![0-9])\.|\.(?![0-9])")


def _too_deep_text(text: str) -> str | None:
    """``line N`` where brackets outside strings and comments nest too deeply, or None.

    tomllib recurses once per nested array or inline table, so a file of thousands of
    ``[`` would end in a RecursionError, and it builds a table per part of a dotted key
    (50 000 parts took 14 GB): this scan is iterative and counts both, a dot that is
    not between two digits (a number's) as one level of the line's key.
    """
    depth, dots, line, pos = 0, 0, 1, 0
    while (m := _TOKENS.search(text, pos)) is not None:
        c, pos = m.group(), m.end()
        if c == "\n":
            line += 1
            dots = 0
        elif c == ".":
            dots += 1
            if depth + dots > MAX_NESTING:
                return f"line {line}"
        elif c == "=":
            dots = 0  # a value follows; an inline table's keys count anew
        elif c == "#":
            end = text.find("\n", pos)
            pos = len(text) if end < 0 else end
        elif c in "\"'":
            quote = c * 3 if text.startswith(c * 2, pos) else c
            end = _string_end(text, m.start() + len(quote), quote)
            line += text.count("\n", pos, end)
            pos = end
        elif c in "[{":
            depth += 1
            if depth > MAX_NESTING:
                return f"line {line}"
        else:
            depth = max(depth - 1, 0)
    return None


def _string_end(text: str, pos: int, quote: str) -> int:
    """The index after the string's closing quote (or the text's end: tomllib complains)."""
    while (end := text.find(quote, pos)) >= 0:
        backslashes = len(text[pos:end]) - len(text[pos:end].rstrip("\\"))
        if quote[0] == "'" or backslashes % 2 == 0:
            return end + len(quote)
        pos = end + 1
    return len(text)


def _too_deep_data(data: dict[str, Any]) -> str | None:
    """The dotted key where parsed tables nest too deeply (``a.b.c = 1`` has no brackets)."""
    stack: list[tuple[str, Any, int]] = [("", data, 0)]
    while stack:
        key, value, depth = stack.pop()
        if depth > MAX_NESTING:
            return key
        if isinstance(value, dict):
            stack.extend((f"{key}.{k}" if key else k, v, depth + 1) for k, v in value.items())
        elif isinstance(value, list):
            stack.extend((key, v, depth + 1) for v in value)
    return None
