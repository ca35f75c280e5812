"""How the e-stop server answers a ``std_srvs/SetBool`` call
(``nodes/estop.py``; the property tests call :func:`step`).  Contract:
``EStop`` in ``contracts/robot.rcl``: the answer's ``success`` is the
brake's state after the call, not whether the call worked."""


def step(engage):
    """``engage``: the request's ``data`` (True: engage the brake, False:
    release it).  Returns ``{"engaged": the brake's state after the call}``."""
    return {"engaged": bool(engage)}
