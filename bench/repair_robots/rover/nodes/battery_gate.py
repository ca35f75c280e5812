"""BatteryGate's logic: low at LOW_VOLTAGE or less."""

LOW_VOLTAGE = 11.5  # V


def step(voltage):
    """``voltage``: the battery's voltage (V).  Returns ``{"low": whether it is LOW_VOLTAGE or less}``."""
    low = voltage <= LOW_VOLTAGE
    return {"low": low}
