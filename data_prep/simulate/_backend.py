"""Lazy access to Warp and Newton (heavy imports, kernel compilation on first use).

``import data_prep.simulate`` must stay cheap and must work where Newton is absent (the
learned model never needs it), so the simulator imports them only when it runs.
"""

from __future__ import annotations

from types import ModuleType


def import_warp() -> ModuleType:
    """``warp``, initialised quietly on the CPU (one home:
    :func:`gnngarment.geometry.signed_distance.import_warp`; the dataset builder runs
    thousands of simulations and its log should show only their reports)."""
    from gnngarment.geometry.signed_distance import import_warp as quiet_warp

    return quiet_warp()


def import_newton() -> ModuleType:
    """``newton`` (and Warp initialised through :func:`import_warp`).

    Raises:
        ImportError: newton is not installed (with the pip command that fixes it).
    """
    import_warp()
    try:
        import newton
    except ImportError as error:  # pragma: no cover - depends on the environment
        raise ImportError(
            "the reference cloth simulation needs NVIDIA Newton: pip install 'newton>=1.8'"
        ) from error
    return newton
