"""cdbo: Coordinate Descent Bayesian Optimisation for learning to race, from Python.

The library's optimisers (``Optimizer``), persistent studies (``Study``, the same SQLite
file as ``cdbo study``), tracks, cars, the simulator and the policy, the limit lap, the
library's own race loop (``race``) and a gymnasium-style environment (``RaceEnv``,
registered as ``cdbo/Race-v0`` when gymnasium is installed).
"""

from ._cdbo import (
    DEFAULT_BETA,
    DEFAULT_BOX_RADIUS,
    LEARNING_OFF_TRACK_MARGIN,
    METHODS,
    PRESETS,
    Car,
    LapResult,
    Limit,
    Optimizer,
    Policy,
    RaceResult,
    Simulator,
    Study,
    Track,
    Trial,
    __version__,
    limit,
    race,
)
from .env import RaceEnv

__all__ = [
    "DEFAULT_BETA",
    "DEFAULT_BOX_RADIUS",
    "LEARNING_OFF_TRACK_MARGIN",
    "METHODS",
    "PRESETS",
    "Car",
    "LapResult",
    "Limit",
    "Optimizer",
    "Policy",
    "RaceEnv",
    "RaceResult",
    "Simulator",
    "Study",
    "Track",
    "Trial",
    "__version__",
    "limit",
    "race",
]

try:  # gymnasium is optional: without it RaceEnv is a plain class.
    from .env import register as _register

    _register()
except ImportError:
    pass
