"""Printing numbers in a lesson so that its stored outputs are the same on every machine.

Round-off (an error of 1e-15 on one CPU, 3e-16 on another) is printed as a bound, not as its
digits; everything above the bound is printed as usual.
"""

from __future__ import annotations

__all__ = ["roundoff"]


def roundoff(x: float, below: float = 1e-10) -> str:
    """``"< 1e-10"`` when ``|x| < below``, else ``x`` in the ``.1e`` format (``"3.2e-04"``).

    x : a real number (an error, a residual); below : float > 0, the bound under which the digits
    are round-off and differ between machines and library versions.
    """
    if not below > 0:
        raise ValueError(f"below must be > 0, got {below}")
    x = float(x)
    return f"< {below:.0e}" if abs(x) < below else f"{x:.1e}"
