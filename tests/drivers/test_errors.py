"""The drivers' error root: a session catches devices' errors without knowing the device."""

from __future__ import annotations

import pytest

from drivers.errors import ClosedError, DeviceError, DeviceTimeoutError, DriveError, GaugeError
from drivers.gauge_stream import GaugeClosedError, GaugeConnectionError
from drivers.unidrive_wire import (
    DriveAddressError,
    DriveConnectionError,
    DriveTimeoutError,
    DriveValueError,
)


@pytest.mark.parametrize(
    ("error", "roots"),
    [
        (DriveConnectionError, (DriveError, ConnectionError)),
        (DriveTimeoutError, (DriveError, DeviceTimeoutError, TimeoutError)),
        (DriveAddressError, (DriveError, LookupError)),
        (DriveValueError, (DriveError, ValueError)),
        (GaugeConnectionError, (GaugeError, ConnectionError)),
        (GaugeClosedError, (GaugeError, ClosedError, RuntimeError)),
        (ClosedError, (RuntimeError,)),
        (DeviceTimeoutError, (TimeoutError,)),
    ],
)
def test_every_device_error_has_the_root_and_its_builtin(
    error: type[Exception], roots: tuple[type[Exception], ...]
) -> None:
    assert issubclass(error, DeviceError)
    for root in roots:
        assert issubclass(error, root)


def test_a_closed_gauge_stream_raises_under_the_root() -> None:
    from drivers.calibration import GaugeCalibration
    from drivers.gauge_stream import SerialGaugeStream

    class Silent:  # a serial port that never has anything to read
        in_waiting = 0

        def read(self, size: int = 1) -> bytes:
            return b""

        def reset_input_buffer(self) -> None:
            pass

        def close(self) -> None:
            pass

    stream = SerialGaugeStream(Silent(), GaugeCalibration(), read_timeout_s=0.01)
    stream.close()
    with pytest.raises(DeviceError):
        stream.drain()
