"""The `manisoft` module's Python half: spaces and the vector reach environment.

The build compiles this file into the module, which runs it in its own namespace when it loads
(python_side.cpp), so everything here is `manisoft.<name>`; it uses the compiled classes
(ReachEnv, TaskEnv, _ReachBatch, _TaskBatch) as globals of that namespace.

Spaces follow Gymnasium's (gymnasium is not needed):
  Box(low, high, shape, dtype)  arrays within [low, high]; low = -inf / high = inf where unbounded
  Dict(spaces)                  a dict of spaces (observations)
  Text(max_length)              a str (the instruction)
  Sequence(space)               a stack of any number of entries of `space` (the objects' poses)
each with .sample() (its own numpy Generator; .seed(s) makes the draws repeatable) and .contains(x).

make_vec_env("reach" or a task, num_envs, ...) is B arms stepped by one call over a pool of
threads, with Gymnasium 1.x's VectorEnv API and its NEXT_STEP autoreset (metadata["autoreset_mode"]).
"""

import enum
import os
import weakref

import numpy as np


class Space:
    """A set of values with a random sampler of its own (numpy Generator)."""

    def __init__(self, shape, dtype, seed=None):
        self.shape = None if shape is None else tuple(int(s) for s in shape)
        self.dtype = None if dtype is None else np.dtype(dtype)
        self._np_random = None
        if seed is not None:
            self.seed(seed)

    @property
    def np_random(self):
        """The space's generator (from fresh entropy until seed() is called)."""
        if self._np_random is None:
            self._np_random = np.random.default_rng()
        return self._np_random

    def seed(self, seed=None):
        """Seeds the sampler; the same seed gives the same samples. Returns [seed]."""
        self._np_random = np.random.default_rng(seed)
        return [seed]

    def __contains__(self, x):
        return self.contains(x)


class Box(Space):
    """Arrays of `shape` and `dtype` with low <= x <= high entry by entry (Gymnasium's Box).

    low / high are scalars or arrays broadcast to `shape`; -inf / inf mark unbounded entries (float
    dtypes only). contains(x): x is an array of this shape whose dtype casts safely to `dtype`
    (numpy.can_cast) and within the bounds (NaN is not). sample(): uniform where bounded on both
    sides, exponential beyond a one-sided bound, normal where unbounded; integers uniform.
    """

    def __init__(self, low, high, shape=None, dtype=np.float64, seed=None):
        dtype = np.dtype(dtype)
        if shape is None:
            shape = np.broadcast(np.asarray(low), np.asarray(high)).shape
        super().__init__(shape, dtype, seed)
        low = np.broadcast_to(np.asarray(low, dtype=np.float64), self.shape)
        high = np.broadcast_to(np.asarray(high, dtype=np.float64), self.shape)
        if np.isnan(low).any() or np.isnan(high).any():
            raise ValueError("Box: low and high must not be NaN")
        if (low > high).any():
            raise ValueError(f"Box: low > high at {np.argwhere(low > high)[0].tolist()}")
        if dtype.kind in "iub" and not (np.isfinite(low).all() and np.isfinite(high).all()):
            raise ValueError(f"Box: an integer Box ({dtype}) needs finite low and high")
        self.low = low.astype(dtype)
        self.high = high.astype(dtype)
        self.low.flags.writeable = False
        self.high.flags.writeable = False

    def is_bounded(self, manner="both"):
        below, above = np.isfinite(self.low).all(), np.isfinite(self.high).all()
        return {"both": below and above, "below": below, "above": above}[manner]

    def sample(self):
        rng = self.np_random
        if self.dtype.kind in "iub":
            return rng.integers(self.low, self.high, size=self.shape, endpoint=True).astype(self.dtype)
        low, high = self.low.astype(np.float64), self.high.astype(np.float64)
        below, above = np.isfinite(low), np.isfinite(high)
        out = rng.normal(size=self.shape)
        lower = below & ~above
        out[lower] = low[lower] + rng.exponential(size=self.shape)[lower]
        upper = above & ~below
        out[upper] = high[upper] - rng.exponential(size=self.shape)[upper]
        both = below & above
        out[both] = rng.uniform(low[both], high[both])
        return out.astype(self.dtype)

    def contains(self, x):
        if not isinstance(x, np.ndarray):  # Python numbers and lists: taken in the Box's dtype
            try:
                x = np.asarray(x, dtype=self.dtype)
            except (ValueError, TypeError, OverflowError):
                return False
        if x.shape != self.shape or x.dtype.kind not in "biuf" or not np.can_cast(x.dtype, self.dtype):
            return False
        return bool(np.all(x >= self.low) and np.all(x <= self.high))

    def __repr__(self):
        return f"Box({self.low.min()}, {self.high.max()}, {self.shape}, {self.dtype})"

    def __eq__(self, other):
        return (isinstance(other, Box) and self.shape == other.shape and self.dtype == other.dtype
                and np.array_equal(self.low, other.low) and np.array_equal(self.high, other.high))


class Text(Space):
    """Strings of min_length..max_length characters (the instruction): contains(x) checks that x is
    a str of such a length; sample() draws characters from `charset`."""

    def __init__(self, max_length, min_length=0, charset="abcdefghijklmnopqrstuvwxyz ", seed=None):
        super().__init__((), None, seed)
        if not 0 <= min_length <= max_length:
            raise ValueError(f"Text: need 0 <= min_length ({min_length}) <= max_length ({max_length})")
        self.min_length, self.max_length, self.charset = int(min_length), int(max_length), str(charset)

    def sample(self):
        n = int(self.np_random.integers(self.min_length, self.max_length, endpoint=True))
        return "".join(self.np_random.choice(list(self.charset), size=n))

    def contains(self, x):
        return isinstance(x, str) and self.min_length <= len(x) <= self.max_length

    def __repr__(self):
        return f"Text({self.min_length}, {self.max_length})"


class Sequence(Space):
    """Any number k >= 0 of values of `space` stacked into one array of shape (k, *space.shape)
    (the objects' poses: as many as the scene has). sample() draws k from a geometric law."""

    def __init__(self, space, seed=None):
        self.feature_space = space
        super().__init__(None, space.dtype, seed)

    def seed(self, seed=None):
        result = super().seed(seed)
        self.feature_space.seed(None if seed is None else int(self.np_random.integers(2**32)))
        return result

    def sample(self):
        k = int(self.np_random.geometric(0.25)) - 1
        return np.stack([self.feature_space.sample() for _ in range(k)]) if k else \
            np.zeros((0,) + self.feature_space.shape, self.feature_space.dtype)

    def contains(self, x):
        x = np.asarray(x)
        return x.ndim == 1 + len(self.feature_space.shape) and all(self.feature_space.contains(e) for e in x)

    def __repr__(self):
        return f"Sequence({self.feature_space!r})"


class Dict(Space):
    """A dict of spaces (Gymnasium's Dict): samples are dicts with the same keys; contains(x) checks
    that x is a dict with exactly these keys, each value in its space."""

    def __init__(self, spaces, seed=None):
        self.spaces = dict(spaces)
        super().__init__(None, None, seed)

    def seed(self, seed=None):
        result = super().seed(seed)
        for space in self.spaces.values():
            space.seed(None if seed is None else int(self.np_random.integers(2**32)))
        return result

    def sample(self):
        return {key: space.sample() for key, space in self.spaces.items()}

    def contains(self, x):
        return isinstance(x, dict) and x.keys() == self.spaces.keys() and \
            all(space.contains(x[key]) for key, space in self.spaces.items())

    def __getitem__(self, key):
        return self.spaces[key]

    def __iter__(self):
        return iter(self.spaces)

    def __len__(self):
        return len(self.spaces)

    def keys(self):
        return self.spaces.keys()

    def items(self):
        return self.spaces.items()

    def __repr__(self):
        return "Dict(" + ", ".join(f"{k!r}: {s!r}" for k, s in self.spaces.items()) + ")"


INSTRUCTION_MAX_LENGTH = 1024  # characters; the benchmark's instructions are one sentence


def _observation_entry(shape, dtype):
    """The space of one observation entry from the environment's (shape, dtype) description."""
    if dtype == "str":
        return Text(INSTRUCTION_MAX_LENGTH, min_length=1)
    if dtype == "uint8":
        return Box(0, 255, shape, np.uint8)  # the camera image
    if shape and shape[0] == -1:
        return Sequence(Box(-np.inf, np.inf, shape[1:], dtype))
    if np.dtype(dtype).kind in "iu":
        return Box(0, 1, shape, dtype)  # the gripper state S: 0 open, 1 closed
    return Box(-np.inf, np.inf, shape, dtype)


def _spaces_of(spec_source):
    """(action space, observation space) from an object with _action_space_spec / _observation_space_spec."""
    a = spec_source._action_space_spec()
    action = Box(a["low"], a["high"], tuple(a["shape"]), a["dtype"])
    observation = Dict({key: _observation_entry(tuple(shape), dtype)
                        for key, (shape, dtype) in spec_source._observation_space_spec().items()})
    return action, observation


_env_spaces = weakref.WeakKeyDictionary()  # environment -> (action space, observation space), made once


def _spaces(env):
    if env not in _env_spaces:
        _env_spaces[env] = _spaces_of(env)
    return _env_spaces[env]


for _cls in (ReachEnv, TaskEnv):  # noqa: F821 (the compiled classes, globals of the module)
    _cls.action_space = property(lambda self: _spaces(self)[0], doc="The action space (Box): shape, dtype, low, high")
    _cls.observation_space = property(lambda self: _spaces(self)[1], doc="The observation space (Dict of spaces)")


def batch_space(space, n):
    """The space of n values of `space` stacked along a new leading axis (Box and Dict)."""
    if isinstance(space, Box):
        return Box(np.broadcast_to(space.low, (n,) + space.shape), np.broadcast_to(space.high, (n,) + space.shape),
                   (n,) + space.shape, space.dtype)
    if isinstance(space, Dict):
        return Dict({key: batch_space(s, n) for key, s in space.items()})
    raise TypeError(f"batch_space: cannot batch {space!r}")


class AutoresetMode(str, enum.Enum):
    """Gymnasium 1.x's autoreset modes, with the same values (gymnasium.vector.AutoresetMode(m.value)
    converts); a str enum, so metadata["autoreset_mode"] == "NextStep" holds."""

    NEXT_STEP = "NextStep"
    SAME_STEP = "SameStep"
    DISABLED = "Disabled"


class _VectorEnv:
    """Gymnasium 1.x's VectorEnv API over a compiled batch (the reach and the task batches): reset
    with seeds and reset masks, step, NEXT_STEP autoreset, read-only views, Gymnasium's "_key"
    info masks. A subclass makes the batch and the spaces, and names its arrays."""

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": []}
    render_mode = None
    _OBSERVATIONS = ()
    _INFOS = ()
    _EPISODE = "seeds"  # the batch's array of each arm's episode seed

    def __init__(self, batch, seed):
        self._batch = batch
        self.num_envs = batch.num_envs
        self.num_threads = batch.threads
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self._first_seed = _count(seed, "make_vec_env: seed")
        self._arrays = batch.arrays()
        self._every_arm = np.ones(self.num_envs, dtype=bool)  # the infos' "_key" masks: every arm has every key
        self._every_arm.flags.writeable = False
        self._started = False
        self.closed = False

    def reset(self, *, seed=None, options=None):
        self._check_open()
        options = dict(options or {})
        mask = options.pop("reset_mask", None)
        if options:
            raise ValueError(f"reset: unknown options {sorted(options)} (a vector environment takes reset_mask)")
        seeds = self._seeds(seed)
        if mask is not None:
            mask = np.asarray(mask)
            if mask.dtype != np.bool_ or mask.shape != (self.num_envs,):
                raise ValueError(f"reset: reset_mask must be a bool array of shape ({self.num_envs},), "
                                 f"got {mask.dtype} {mask.shape}")
            if not self._started:
                raise ValueError("reset: the first reset starts every arm (no reset_mask)")
        self._batch.reset(seeds, mask)
        self._started = True
        return self._observations(), self._infos()

    def step(self, actions):
        self._check_open()
        if not self._started:
            raise RuntimeError("call reset() before step()")
        a = np.asarray(actions)
        if a.dtype.kind not in "fiu":
            raise ValueError(f"step: actions dtype must be real (float64 preferred), got {a.dtype}")
        if a.shape != self.action_space.shape:
            raise ValueError(f"step: actions must have shape {self.action_space.shape} {self._ACTION_LAYOUT}, got {a.shape}")
        self._batch.step(np.ascontiguousarray(a, dtype=np.float64))
        arrays = self._arrays
        return (self._observations(), arrays["rewards"], arrays["terminated"], arrays["truncated"], self._infos())

    def close(self, **kwargs):
        """Stops the batch's threads and frees its arms; later calls raise RuntimeError."""
        if not self.closed:
            self._arrays = None
            self._batch = None
            self.closed = True

    @property
    def unwrapped(self):
        return self

    @property
    def np_random(self):
        return self.single_action_space.np_random

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def _check_open(self):
        if self.closed:
            raise RuntimeError("the vector environment is closed")

    def _seeds(self, seed):
        n = self.num_envs
        if seed is None:
            if not self._started:
                return self._first_seed + np.arange(n, dtype=np.uint64)
            return self._arrays[self._EPISODE] + np.uint64(n)
        if isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
            return _count(seed, "reset: seed") + np.arange(n, dtype=np.uint64)
        seeds = [_count(s, f"reset: seed[{i}]") for i, s in enumerate(seed)]
        if len(seeds) != n:
            raise ValueError(f"reset: seed holds {len(seeds)} values, expected num_envs = {n}")
        return np.array(seeds, dtype=np.uint64)

    def _observations(self):
        return {key: self._arrays[key] for key in self._OBSERVATIONS}

    def _infos(self):
        infos = {key: self._arrays[key] for key in self._INFOS}
        infos["seed"] = self._arrays[self._EPISODE]
        for key in list(infos):
            infos["_" + key] = self._every_arm
        return infos


def _checked_counts(num_envs, num_threads):
    num_threads = (os.cpu_count() or 1) if num_threads is None else num_threads
    if isinstance(num_envs, bool) or not isinstance(num_envs, (int, np.integer)) or num_envs < 1:
        raise ValueError(f"make_vec_env: num_envs = {num_envs!r} must be an int >= 1")
    if isinstance(num_threads, bool) or not isinstance(num_threads, (int, np.integer)) or num_threads < 1:
        raise ValueError(f"make_vec_env: num_threads = {num_threads!r} must be an int >= 1")
    return int(num_envs), int(num_threads)


class ReachVectorEnv(_VectorEnv):
    """num_envs reach environments stepped together (Gymnasium 1.x VectorEnv API, without gymnasium).

    Arm i of the batch follows exactly the trajectory of make_env("reach", target_set, horizon=...)
    given the same seeds and actions, whatever num_threads and i.

    reset(seed=None, options=None) -> (observations, infos)
      seed: an int s (arm i gets s + i), a list of num_envs ints, or None (arm i continues its own
      seed sequence: its current episode's seed + num_envs; the first reset uses make_vec_env's seed
      + i). options={"reset_mask": bool array of num_envs}: only those arms reset (the others keep
      their state; their entries in the returned arrays are their current ones).
    step(actions) -> (observations, rewards, terminations, truncations, infos)
      actions: num_envs x rows x 3 torques (any real dtype, lists accepted; converted to float64),
      clamped to the actuation limits like the single environment's. A non-finite action raises
      ValueError naming the arm (env index) and the entry, and no arm changes.
    Autoreset NEXT_STEP (Gymnasium 1.x's default): an arm whose episode ended (terminated: its
    simulation diverged; truncated: the horizon) in one step is reset by the next step, whose action
    for that arm is ignored, returning the new episode's first observation, reward 0 and flags
    False. The new episode's seed is the ended one's + num_envs.

    Rewards: R_d + R_s of the paper (reach_env.hpp); stability_beta is R_s's beta (0: R_d alone).
    Observations: dict of end_effector, target (B x 4 x 4), node_positions, node_velocities
    (B x m x 3). Infos: dict of arrays of leading dimension B: success, steps, position_error,
    rotation_error, clipped, max_node_speed, seed, each with Gymnasium's mask "_key" (a bool array
    of B saying which arms have the key: every arm has every key, so it is all True).
    Arrays: every returned array is a read-only numpy view of the batch's own buffers (no copy):
    the next reset or step overwrites it; copy (np.array(x)) what you keep across steps.
    The GIL is released while the batch resets and steps (over num_threads threads).
    """

    _OBSERVATIONS = ("end_effector", "target", "node_positions", "node_velocities")
    _INFOS = ("success", "steps", "position_error", "rotation_error", "clipped", "max_node_speed")
    _ACTION_LAYOUT = "(num_envs, rows, 3)"

    def __init__(self, num_envs, num_threads=None, target_set="table", seed=0, horizon=None, stability_beta=1.0):
        num_envs, num_threads = _checked_counts(num_envs, num_threads)
        horizon = HORIZON if horizon is None else horizon  # noqa: F821 (compiled constant)
        batch = _ReachBatch(num_envs, num_threads, target_set, int(horizon), float(stability_beta))  # noqa: F821
        self.horizon = int(horizon)
        self.single_action_space, self.single_observation_space = _spaces_of(batch)
        del self.single_observation_space.spaces["time"]  # the batch observes no time (infos["steps"] * CONTROL_DT)
        super().__init__(batch, seed)

    def __repr__(self):
        return f"ReachVectorEnv(num_envs={self.num_envs}, num_threads={self.num_threads}, horizon={self.horizon})"


class TaskVectorEnv(_VectorEnv):
    """num_envs environments of one task and setting stepped together (Gymnasium 1.x VectorEnv API),
    with the privileged state observation, and with render=True the camera image.

    Arm i of the batch follows exactly the episode of make_env(task, setting, seed=seed,
    render=False, privileged=True) reset to the same scene and given the same actions, whatever
    num_threads and i.

    Episodes are scenes: arm i's scene is (task, setting, split, index, seed) with make_vec_env's
    dataset seed and an index of its own. reset(seed=s) gives arm i index s + i (a list: one index
    an arm); reset() continues each arm's indices (its current one + num_envs; the first reset:
    make_vec_env's first_index + i). options={"reset_mask": ...} as the reach batch's.
    step(actions): num_envs x (3n + 1) flat actions (torques, then S; the single environment's
    layout), one control step. action_mode="ee_pose": num_envs x 7 end-effector actions (target
    position, rotation vector from the home orientation, S: make_env's ee_pose layout), each arm's
    target tracked by its own model executor for action_repeat control steps (fewer when its
    episode ends; infos["control_steps"]), as make_env(..., action_mode="ee_pose") does;
    infos["ee_command"] says what each command did ("line", "ramp", "kept", "refused").
    Autoreset NEXT_STEP: an ended arm (terminated: success or a terminal failure; truncated: the
    horizon T) starts its next scene (index + num_envs) at the next step, whose action for it is
    ignored.
    Observations: rod_nodes (B x (n + 1) x 3), end_effector, gripper_pose (B x 4 x 4),
    gripper_width (B), gripper_state (B), object_poses (B x K x 4 x 4: the first object_count[i]
    are arm i's objects, the others zero), object_count (B), instruction (a tuple of B str);
    render=True: image (B x H x W x 3 uint8), each arm's camera image drawn on the worker thread
    that stepped it (a renderer per arm), the pixels make_env(..., render=True, camera=camera)
    gives in the same state; camera: as make_env's (a dict replacing each scene's camera; None:
    each scene's own at 514 x 514). A rendering environment is used from the thread of its first
    reset.
    Infos: success, steps, control_steps (the step's), failure (the task layer's reason: None or a
    name, a tuple of B), seed (each arm's scene index), with Gymnasium's "_key" masks. Arrays are
    read-only views of the batch's buffers, overwritten by the next reset or step (copy what you
    keep).
    """

    _OBSERVATIONS = ("rod_nodes", "end_effector", "gripper_pose", "gripper_width", "gripper_state", "object_poses", "object_count")
    _INFOS = ("success", "steps", "control_steps")
    _EPISODE = "indices"

    def __init__(self, task, num_envs, num_threads=None, setting="clean", split="train", seed=0, first_index=0,
                 action_mode="torque", action_repeat=None, render=False, camera=None):
        num_envs, num_threads = _checked_counts(num_envs, num_threads)
        self.task, self.setting, self.split, self.action_mode = task, setting, split, action_mode
        self.action_repeat = 1 if action_mode == "torque" else (ACTION_REPEAT if action_repeat is None else int(action_repeat))  # noqa: F821
        self._ACTION_LAYOUT = "(num_envs, 7)" if action_mode == "ee_pose" else "(num_envs, 3n + 1)"
        batch = _TaskBatch(task, setting, split, _count(seed, "make_vec_env: seed"), num_envs, num_threads, action_mode,  # noqa: F821
                           self.action_repeat, bool(render), camera)
        self.horizon = HORIZON  # noqa: F821 (compiled constant)
        self.single_action_space, _ = _spaces_of(batch)
        n, k = batch.n_elements, batch.max_objects
        unbounded = lambda *shape: Box(-np.inf, np.inf, shape, np.float64)  # noqa: E731
        self.single_observation_space = Dict({
            "rod_nodes": unbounded(n + 1, 3), "end_effector": unbounded(4, 4), "gripper_pose": unbounded(4, 4),
            "gripper_width": unbounded(), "gripper_state": Box(0, 1, (), np.int64), "object_poses": unbounded(k, 4, 4),
            "object_count": Box(0, k, (), np.int64)})
        if batch.image_size is not None:
            self.single_observation_space.spaces["image"] = Box(0, 255, (*batch.image_size, 3), np.uint8)
            self._OBSERVATIONS = self._OBSERVATIONS + ("image",)
        self._instructions = None
        super().__init__(batch, first_index)

    def _observations(self):
        obs = super()._observations()
        if self._instructions is None or not self._arrays["steps"].all():  # an arm started a scene
            self._instructions = tuple(self._batch.instructions())
        obs["instruction"] = self._instructions
        return obs

    def _infos(self):
        infos = super()._infos()
        infos["failure"] = self._batch.failures()
        infos["_failure"] = self._every_arm
        if self.action_mode == "ee_pose":
            infos["ee_command"] = self._batch.ee_commands()
            infos["_ee_command"] = self._every_arm
        return infos

    def __repr__(self):
        return (f"TaskVectorEnv({self.task!r}, num_envs={self.num_envs}, num_threads={self.num_threads}, setting={self.setting!r}, "
                f"action_mode={self.action_mode!r})")


def _count(value, what):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0 or value >= 2**64:
        raise ValueError(f"{what} = {value!r} must be an int in [0, 2**64)")
    return np.uint64(value)


def make_vec_env(name, num_envs, num_threads=None, **kwargs):
    """num_envs environments stepped together by one call over num_threads threads (default: the
    machine's cores), Gymnasium 1.x VectorEnv API, NEXT_STEP autoreset:
      make_vec_env("reach", num_envs, num_threads=None, target_set="table"|"equilibria", seed=0,
                    horizon=HORIZON, stability_beta=1.0) -> ReachVectorEnv
      make_vec_env(task, num_envs, num_threads=None, setting="clean", split="train", seed=0,
                    first_index=0, action_mode="torque"|"ee_pose", action_repeat=36, render=False,
                    camera=None) -> TaskVectorEnv
                    (a task of manisoft.tasks(), privileged state observations; render=True adds the image)"""
    if name == "reach":
        return ReachVectorEnv(num_envs, num_threads, **kwargs)
    names = [t["name"] for t in tasks()]  # noqa: F821 (compiled function)
    if name not in names:
        raise ValueError(f"make_vec_env: unknown environment {name!r} (available: {', '.join(names)}, reach)")
    return TaskVectorEnv(name, num_envs, num_threads, **kwargs)


del _cls
