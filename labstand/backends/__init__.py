"""Device backends: one module each, registered by name in ``labstand.session.devices``.

Each module has a factory ``open_NAME(request: DeviceRequest) -> Devices``; the session
package imports them only by name, so it never sees a concrete driver.
"""

__all__: list[str] = []
