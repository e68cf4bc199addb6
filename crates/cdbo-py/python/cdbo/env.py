"""A gymnasium-style episodic environment: one step is one lap.

The action is the policy's weights w (M = ``kernels`` of them), the reward the lap's
L/T in m/s (0 when the lap fails), and every episode ends after its one lap. ``info``
tells the lap time, whether and where the lap failed. ``env.w0`` is the demonstration's
fitted policy, the start every method is given (``cdbo race`` starts from the same).
"""

from __future__ import annotations

import numpy as np

from ._cdbo import (
    DEFAULT_BOX_RADIUS,
    Optimizer,
    Policy,
    Simulator,
    resolve_line,
    resolve_stack,
)

try:
    import gymnasium as _gym
    from gymnasium import spaces as _spaces

    _Base = _gym.Env
except ImportError:  # a plain class without gymnasium
    _gym = None
    _spaces = None
    _Base = object


class _Box:
    """The action box [w0 - r, w0 + r] when gymnasium is not installed."""

    def __init__(self, low, high):
        self.low = np.asarray(low, dtype=np.float64)
        self.high = np.asarray(high, dtype=np.float64)
        self.shape = self.low.shape
        self.dtype = np.dtype(np.float64)

    def contains(self, x):
        x = np.asarray(x, dtype=np.float64)
        return x.shape == self.shape and bool(np.all((x >= self.low) & (x <= self.high)))

    def sample(self, rng=None):
        rng = rng if rng is not None else np.random.default_rng()
        return rng.uniform(self.low, self.high)


def _box(low, high):
    if _spaces is None:
        return _Box(low, high)
    return _spaces.Box(low=np.asarray(low), high=np.asarray(high), dtype=np.float64)


class RaceEnv(_Base):
    """Racing one track: ``RaceEnv(track="ridgeway", car="spirit-300", kernels=30)``.

    ``reset()`` returns ``(obs, info)`` and ``step(w)`` returns ``(obs, reward, terminated,
    truncated, info)`` with ``terminated=True``: each episode is one lap. The observation is
    a constant (there is nothing to observe before a lap). ``action_space`` is [-1, 1]^d,
    symmetric and normalised as gymnasium asks: ``step(u)`` drives the weights
    ``w = w0 + bounds * u`` (``weights(u)``), which span the box [``low``, ``high``] =
    [w0 - bounds, w0 + bounds] the library's optimisers search; ``lap(w)`` drives weights
    directly. Actions are not clipped.
    ``w0``, ``lengthscale`` and ``track_length`` (m) are what ``cdbo.Optimizer`` is told to
    race as ``cdbo race`` does.

    ``line`` is the line the car holds, as ``cdbo race --line``: ``"centre"`` (the paper),
    ``"min-curvature"`` (the fixed racing line; the demonstration holds it too) or ``"learn"``:
    the action is then [w_a, w_d], the pedal's ``kernels`` weights and a line d(x) on
    ``line_kernels`` kernels (default ``kernels``) at length-scale ``line_lengthscale``, an
    offset from ``line_start`` (``"centre"`` or ``"min-curvature"``); ``w0``'s line is 0.
    ``base_line`` and ``line_kernels`` say what was resolved.

    ``steering`` is how the car steers, as ``cdbo race --steering``: ``"pi"`` (the paper's)
    or ``"tracker"`` (the path tracker); ``off_track_margin`` is where a lap leaves the road,
    as ``--off-track-margin``: the car's centre that many metres past its edge (negative:
    inside the road; 1 is the game's rule); by default (None) the reserve ``cdbo race`` learns
    with, kept for the game or car the policy is then driven in: the wheels 0.25 m off
    slippery ground, the body 1 m off the walls, the car's centre on the road
    (``LEARNING_OFF_TRACK_MARGIN``, 1 m inside it, where the road's verges are not known).

    ``preset="fast-safe"``, as ``cdbo race --preset fast-safe``, stands for the recommended
    stack in place of ``line`` and ``steering`` (which are then refused): the path tracker on
    the minimum-curvature line, and ``optimizer()``'s method the safe pattern search.
    """

    metadata = {"render_modes": []}

    def __init__(
        self,
        track="ridgeway",
        car="spirit-300",
        kernels: int = 30,
        demo_speed=None,
        bounds: float = DEFAULT_BOX_RADIUS,
        data_dir=None,
        line=None,
        line_kernels=None,
        line_start=None,
        steering=None,
        off_track_margin=None,
        preset=None,
    ):
        self.preset = preset
        self.method, steering, line = resolve_stack(
            preset,
            steering=steering,
            line=line,
            line_kernels=line_kernels,
            line_start=line_start,
        )
        self.base_line, self.line_kernels = resolve_line(
            kernels, line=line, line_kernels=line_kernels, line_start=line_start
        )
        self.simulator = Simulator(
            track,
            car,
            data_dir=data_dir,
            line=self.base_line,
            steering=steering,
            off_track_margin=off_track_margin,
        )
        # The recommended learner starts from the profile start, as `cdbo race` does, unless a
        # demonstration speed is given; every other method from the paper's 15 m/s.
        # From the profile start the policy's action asks for a speed (``target``, as
        # ``RaceResult.best_target``), as the race's does; otherwise it is the pedal.
        profile = None
        self.target = None
        if demo_speed is None and self.method == "safe-pattern-search":
            profile = self.simulator.demonstrate_profile()
        if profile is not None:
            demo, x, a, demo_speed, self.target = profile
        else:
            demo_speed = 15.0 if demo_speed is None else demo_speed
            demo, x, a = self.simulator.demonstrate(demo_speed)
        if not demo.completed:
            raise ValueError(
                f"the {demo_speed} m/s demonstration does not complete "
                f"{self.simulator.track.name} ({demo.failure}): choose a slower demo_speed"
            )
        self.demo = demo
        self.initial = Policy.fit(x, a, kernels)
        self.kernels = kernels
        self.lengthscale = self.initial.lengthscale
        m = self.line_kernels or 0
        # The paper's length-scale 1/(M_d - 1), as the race's line block.
        self.line_lengthscale = Policy(np.zeros(m)).lengthscale if m else None
        self.w0 = np.concatenate([self.initial.weights, np.zeros(m)])
        self.track_length = self.simulator.track.length
        self.bounds = bounds
        self.low, self.high = self.w0 - bounds, self.w0 + bounds
        self.action_space = _box(-np.ones_like(self.w0), np.ones_like(self.w0))
        self.observation_space = _box(np.zeros(1), np.ones(1))
        self.last = None

    def optimizer(self, method=None, **options):
        """``cdbo.Optimizer(method, w0, ...)`` told what this race is: its start ``w0``, its
        box, the policy's length-scale, the lap's length and, with a learned line, how many
        weights are the pedal's, as ``cdbo race`` tells it (the
        pattern search pushes the policy's pedal and repairs it over road with them).
        ``method`` is ``"cdbo"`` by default, the preset's learner with a ``preset`` (which
        refuses another). ``options`` are the Optimizer's own (``seed=``, ``knob=``,
        ``max_failed=``, ...)."""
        method = resolve_stack(self.preset, method=method)[0]
        options.setdefault("bounds", self.bounds)
        options.setdefault("lengthscale", self.lengthscale)
        options.setdefault("track_length", self.track_length)
        if self.line_kernels:
            options.setdefault("pedal_kernels", self.kernels)
        return Optimizer(method, self.w0, **options)

    def reset(self, *, seed=None, options=None):
        if _gym is not None:
            super().reset(seed=seed)
        return np.zeros(1), {}

    def weights(self, action):
        """The weights an action u in [-1, 1]^d stands for: ``w0 + bounds * u``."""
        u = np.asarray(action, dtype=np.float64)
        if u.shape != self.w0.shape:
            raise ValueError(f"the action has {u.size} weights; this race's have {self.w0.size}")
        return self.w0 + self.bounds * u

    def step(self, action):
        return self._drive(self.weights(action))

    def _drive(self, w):
        w = np.asarray(w, dtype=np.float64)
        if w.shape != self.w0.shape:
            raise ValueError(f"the action has {w.size} weights; this race's have {self.w0.size}")
        policy = Policy(w[: self.kernels], self.lengthscale)
        line = Policy(w[self.kernels :], self.line_lengthscale) if self.line_kernels else None
        lap = self.simulator.lap(policy, line=line, target=self.target)
        self.last = lap
        info = {
            "completed": lap.completed,
            "lap_time": lap.time,
            "failure": lap.failure,
            "x_fail": lap.x_fail,
            "too_slow": lap.failure in ("stalled", "time_limit"),
        }
        return np.zeros(1), lap.reward, True, False, info

    def lap(self, w):
        """One lap with weights ``w`` (not an action: the optimiser's weights): its ``LapResult``.

        ``opt.tell(w, env.lap(w))`` tells the optimiser the reward and, for a failed lap,
        where and why it failed; ``float(env.lap(w))`` is the reward alone.
        """
        self._drive(w)
        return self.last


def register():
    """Registers ``cdbo/Race-v0`` with gymnasium (raises ImportError without it)."""
    import gymnasium

    if "cdbo/Race-v0" not in gymnasium.registry:
        gymnasium.register(id="cdbo/Race-v0", entry_point="cdbo.env:RaceEnv")
