#!/usr/bin/env python3
"""The reference policy from privileged state on the end-effector track: behaviour cloning of the
expert's end-effector targets (obs/ee_target of a generated dataset) by a small MLP per task,
trained on CPU with PyTorch (Debian python3-torch), evaluated by evaluate.py like any policy. It is
the bound a perfect perception gives a policy that learns from the dataset.

    generate_dataset --tasks ALN,COLL --clean 400 --randomized 400 --seed 0 --out data/ref
    /usr/bin/python3 -m manisoft.reference_policy train --data data/ref --out ref/models
    MANISOFT_REFERENCE_MODELS=ref/models /usr/bin/python3 -m manisoft.evaluate --task ALN --setting all \\
        --policy python:manisoft.reference_policy:act --observation privileged --action-mode ee_pose --out ref/eval

Observation (what evaluate.py --observation privileged hands over: the environment's privileged
state and the episode's scene JSON, whose goal and assets a perfect perception would read off the
image and the instruction): the end-effector frame, the finger width and S, the task's objects in
the goal's roles (the moved object first; COLL then the container), OVR's obstacle, the goal
(ALN, OVR: the marker's pose), the moved object's asset, and the policy's own memory: its previous
command and that command's change from the one before, the end effector's displacement since its
last call, the control steps since the command was first sent, the commands since S last changed.
Action: the end-effector track's 7 floats (target position, rotation vector from the home
orientation, S), sent every --action-repeat control steps (evaluate.py's default, 36: 20 Hz).
Model: an MLP (3 x 256, SiLU) to two answers: whether to switch to a new command now (a logit),
and the next command: its position a softmax-weighted choice among anchors (the previous command,
the moved object, the end effector at the goal, the goal or container, the end effector) plus a
residual, its rotation vector a change from the previous command's, S a logit. The policy keeps
its previous command until the switch logit is positive, so the track is not restarted by the
regression's small differences, and the next command is never an average of two waypoints: it is
the one after the previous command's.
Training samples: every --stride-th control step t of the train mask's episodes, the previous
command being the expert's target at t - --repeat (the control steps between commands); a new
command starts wherever the target or S changes; the switch label says whether the expert's
command changed since, the next command is the one after that one. Losses: squared pose errors
in units of 1 cm and 0.05 rad, binary cross-entropy of S and of the switch. The dataset's valid
mask gives the held-out loss. A checkpoint is written after every epoch (temporary name, then
renamed); --resume continues from it and ends with the weights an uninterrupted run gives.
"""
import argparse
import json
import os
import sys
import time

import numpy as np

TASKS = ("COLL", "ALN", "OVR")
ANCHORS = 5  # points the next command's position is chosen among (features' last columns)
POSITION_SCALE, ROTATION_SCALE = 0.01, 0.05  # m, rad: a pose error of this size costs 1 in the loss
MAX_OBJECTS = 2  # the objects of a task's goal roles (COLL: object, container; ALN, OVR: the object)


# ---- features

def rotation_of_quaternion(q):
    """(..., 4) w x y z -> (..., 3, 3)."""
    w, x, y, z = (q[..., i] for i in range(4))
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1)], -2)


def pose_of_json(p):
    return np.asarray(p["position"], dtype=np.float64), np.asarray(p["rotation"], dtype=np.float64)


class SceneRoles:
    """What a task's scene fixes for an episode: the objects in their goal roles, the goal pose,
    the obstacle and the moved object's asset."""

    def __init__(self, scene):
        self.task = scene["task"]
        if self.task not in TASKS:
            raise ValueError(f"the reference policy knows the tasks {', '.join(TASKS)}, not {self.task}")
        goal = scene["goal"]
        self.roles = [goal["object"]] + ([goal["container"]] if self.task == "COLL" else [])
        self.asset = scene["objects"][goal["object"]]["asset_id"]
        zero = (np.zeros(3), np.eye(3))
        self.has_goal_pose = "goal_pose" in goal
        self.goal = pose_of_json(goal["goal_pose"]) if self.has_goal_pose else zero
        self.obstacle = pose_of_json(scene["obstacles"][goal["obstacle"]]["pose"])[0] if "obstacle" in goal else np.zeros(3)


def six(r):
    """A rotation's first two columns (..., 6): continuous, unlike angles."""
    return np.concatenate([r[..., :, 0], r[..., :, 1]], -1)


def yaw(r):
    """The heading of a rotation's x axis about world z."""
    return np.arctan2(r[1, 0], r[0, 0])


def turn(angle):
    """An angle as cos, sin of itself and of twice and four times itself (a half and a quarter turn's
    symmetries read the same)."""
    return [np.cos(angle), np.sin(angle), np.cos(2 * angle), np.sin(2 * angle), np.cos(4 * angle), np.sin(4 * angle)]


def features(roles, ee_position, ee_rotation, width, s, object_positions, object_rotations, memory, assets):
    """One row of inputs (see the module's comment). object_* are the scene's objects in its order;
    memory: the policy's previous command (7), its change from the one before, the end effector's
    displacement since the last call, the control steps since the command was first sent and the
    commands since S last changed."""
    previous, change, displacement, age, moves = memory
    parts = [ee_position, six(ee_rotation), [width * 10.0, s], previous[:3] - ee_position, previous[3:], change * 10.0,
             displacement * 10.0, [min(age, 720) / 360.0, min(moves, 8) / 4.0]]
    for k in range(MAX_OBJECTS):
        if k < len(roles.roles):
            p, r = object_positions[roles.roles[k]], object_rotations[roles.roles[k]]
            parts += [p, p - ee_position, six(r), [1.0]]
        else:
            parts += [np.zeros(3), np.zeros(3), np.zeros(6), [0.0]]
    goal_p, goal_r = roles.goal
    moved, moved_r = object_positions[roles.roles[0]], object_rotations[roles.roles[0]]
    parts += [goal_p, goal_p - moved, six(goal_r), roles.obstacle, roles.obstacle - ee_position]
    # headings: the turn the object still needs, and where the object's and the goal's point from the hand's
    parts += [turn(yaw(goal_r) - yaw(moved_r)), turn(yaw(moved_r) - yaw(ee_rotation)), turn(yaw(goal_r) - yaw(ee_rotation))]
    # where the end effector would be with the object at the goal pose, held as it is held now
    # (ALN, OVR: the place's target while carrying; turned about z only, as the goal is upright)
    at_goal = np.zeros(3)
    if roles.has_goal_pose:
        turned = yaw(goal_r) - yaw(moved_r)
        cz, sz = np.cos(turned), np.sin(turned)
        at_goal = goal_p + np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]]) @ (ee_position - moved)
    parts += [at_goal - ee_position, at_goal - previous[:3]]
    one_hot = np.zeros(len(assets))
    if roles.asset in assets:
        one_hot[assets.index(roles.asset)] = 1.0
    parts.append(one_hot)
    # the anchors of the next command's position, from the previous command's (the last ANCHORS x 3
    # columns): itself, the moved object, the end effector at the goal, the goal or container, the
    # end effector
    anchor = object_positions[roles.roles[-1]] if roles.task == "COLL" else goal_p
    for a in (previous[:3], moved, at_goal if roles.has_goal_pose else previous[:3], anchor, ee_position):
        parts.append(a - previous[:3])
    return np.concatenate([np.asarray(p, dtype=np.float64).ravel() for p in parts])


def home_command(ee_position):
    """The track's target after reset: the home pose (rotation vector 0 from the home orientation), S = 0."""
    return np.concatenate([ee_position, np.zeros(4)])


# ---- the dataset

def read_episodes(directory, task):
    """The task's episodes of a generated dataset: (mask name, scene, arrays) each."""
    import h5py
    out = []
    with h5py.File(os.path.join(directory, "dataset.hdf5"), "r") as f:
        masks = {name: {m.decode() for m in f["mask"][name][()]} for name in ("train", "valid")}
        for demo in sorted(f["data"].keys(), key=lambda d: int(d.split("_")[1])):
            g = f["data"][demo]
            if g.attrs["task"] != task:
                continue
            mask = "train" if demo in masks["train"] else "valid"
            arrays = {k: g["obs"][k][()].astype(np.float64) for k in ("eef_pose", "gripper", "object_poses", "ee_target")}
            out.append((mask, json.loads(g.attrs["scene"]), arrays))
    return out


def command_rows(a, steps_at, repeat):
    """The expert's commands (a["ee_target"]) as the policy's memory at each step t of steps_at, with
    the command sent at t - repeat as the previous one: (t, the previous command, its change from the
    one before, the step of the previous call, the control steps since the previous command was first
    sent, the commands since S last changed, the label: the command after the previous one (the next
    command) as a change from it, its S and whether the expert's command changed since (the switch))."""
    target = a["ee_target"]
    steps = len(target)
    # the commands: a new one wherever the target or S changes (obs/ee_waypoint counts pose changes only)
    waypoint = np.concatenate([[0], np.cumsum(np.any(target[1:] != target[:-1], axis=1))])
    # per command: how many commands since S last changed (0 for the one that changed it)
    s_of = target[np.searchsorted(waypoint, np.arange(waypoint[-1] + 1)), 6]
    moves = np.zeros(len(s_of), dtype=np.int64)
    for w in range(1, len(s_of)):
        moves[w] = 0 if s_of[w] != s_of[w - 1] else moves[w - 1] + 1
    first = np.searchsorted(waypoint, np.arange(waypoint[-1] + 2))  # first step of each waypoint (steps if none)
    home = home_command(a["eef_pose"][0, :3])
    for t in steps_at:
        if t >= repeat:
            w = waypoint[t - repeat]
            previous, age, switch = target[t - repeat], t - first[w], waypoint[t] != w
            following = target[first[w + 1]] if first[w + 1] < steps else previous
            before, count = t - repeat, moves[w] + 1
            change = previous - (target[first[w - 1]] if w > 0 else home)
        else:  # the first command: the track holds the home pose
            previous, age, switch, following, before, count = home, t, True, target[0], 0, 0
            change = np.zeros(7)
        label = np.concatenate([following[:6] - previous[:6], following[6:], [float(switch)]])
        yield t, previous, change, before, age, count, label


def samples_of(episode, stride, repeat, assets):
    """The episode's training rows at every stride-th step t (command_rows): the inputs from the
    recorded state and the label."""
    _, scene, a = episode
    roles = SceneRoles(scene)
    eef, grip = a["eef_pose"], a["gripper"]
    steps = len(eef)
    objects = a["object_poses"].reshape(steps, -1, 7)
    ee_rot = rotation_of_quaternion(eef[:, 3:])
    obj_rot = rotation_of_quaternion(objects[..., 3:])
    xs, ys = [], []
    for t, previous, change, before, age, count, label in command_rows(a, range(0, steps, stride), repeat):
        xs.append(features(roles, eef[t, :3], ee_rot[t], grip[t, 0], grip[t, 1], objects[t, :, :3], obj_rot[t],
                           (previous, change, eef[t, :3] - eef[before, :3], age, count), assets))
        ys.append(label)
    return xs, ys


def build_dataset(directories, task, stride, repeat):
    episodes = [e for d in directories for e in read_episodes(d, task)]
    if not episodes:
        raise ValueError(f"{', '.join(directories)}: no {task} episodes")
    assets = sorted({SceneRoles(e[1]).asset for e in episodes if e[0] == "train"})
    split = {"train": ([], []), "valid": ([], [])}
    for e in episodes:
        xs, ys = samples_of(e, stride, repeat, assets)
        split[e[0]][0].extend(xs)
        split[e[0]][1].extend(ys)
    arrays = {m: (np.asarray(x, dtype=np.float32), np.asarray(y, dtype=np.float32)) for m, (x, y) in split.items() if x}
    counts = {m: sum(1 for e in episodes if e[0] == m) for m in ("train", "valid")}
    return arrays, assets, counts


# ---- the model

def build_model(torch, inputs, width=256, depth=3):
    """The MLP: ANCHORS weights (logits), a position residual, a rotation vector change, S and the
    switch (logits)."""
    layers, n = [], inputs
    for _ in range(depth):
        layers += [torch.nn.Linear(n, width), torch.nn.SiLU()]
        n = width
    layers.append(torch.nn.Linear(n, ANCHORS + 3 + 3 + 2))
    return torch.nn.Sequential(*layers)


class Normaliser:
    """The inputs' mean and spread over the training rows."""

    def __init__(self, x):
        self.x_mean, self.x_std = x.mean(0), x.std(0) + 1e-6

    def __call__(self, x):
        return (x - self.x_mean) / self.x_std

    def state(self):
        return {k: v.tolist() for k, v in vars(self).items()}

    def constant_in_own_units(self):
        """A copy passing the columns that were constant over the training rows (the table's height
        of ALN's goal, an absent object's zeros) as their deviation unscaled, not divided by
        __init__'s 1e-6: a model fed inputs that vary there (perceived ones) is not handed a
        millionfold value. The same model on inputs like its training rows answers the same."""
        n = Normaliser.of_state(self.state())
        n.x_std = np.where(n.x_std < 2e-6, 1.0, n.x_std).astype(np.float32)
        return n

    @staticmethod
    def of_state(state):
        n = Normaliser.__new__(Normaliser)
        for k, v in state.items():
            setattr(n, k, np.asarray(v, dtype=np.float32))
        return n


def decode(torch, out, x):
    """The network's answer for raw inputs x: the next command's position and rotation vector as
    changes from the previous command, the S logit and the switch logit. The position is the
    softmax-weighted anchors plus a residual (an output of 1 is 10 cm)."""
    anchors = x[:, -3 * ANCHORS:].reshape(-1, ANCHORS, 3)
    weights = torch.softmax(out[:, :ANCHORS], 1)
    position = (weights[:, :, None] * anchors).sum(1) + 0.1 * out[:, ANCHORS:ANCHORS + 3]
    return position, out[:, ANCHORS + 3:ANCHORS + 6] * ROTATION_SCALE, out[:, -2], out[:, -1]


def loss_of(torch, out, x, y):
    """The pose errors in units of POSITION_SCALE and ROTATION_SCALE squared, the binary
    cross-entropy of S and of the switch."""
    position, rotation, s, switch = decode(torch, out, x)
    pose = (((position - y[:, :3]) / POSITION_SCALE) ** 2).mean() + (((rotation - y[:, 3:6]) / ROTATION_SCALE) ** 2).mean()
    bce = torch.nn.functional.binary_cross_entropy_with_logits
    return pose + bce(s, (y[:, 6] >= 0.5).float()) + bce(switch, y[:, 7])


# ---- training runs (image_policy.py's too)

def save(torch, state, path):
    """torch.save under a temporary name, then renamed: a file under its final name is complete."""
    tmp = path + ".tmp"
    torch.save(state, tmp)
    os.replace(tmp, path)


def resume(torch, checkpoint, model, optimiser, generator, task):
    """A killed run's checkpoint restored into the model, optimiser and generator: its epoch and history."""
    saved = torch.load(checkpoint)
    model.load_state_dict(saved["model"])
    optimiser.load_state_dict(saved["optimiser"])
    generator.set_state(saved["generator"])
    print(f"{task}: resumed after epoch {saved['epoch']}", flush=True)
    return saved["epoch"], saved["history"]


def write_checkpoint(torch, checkpoint, model, optimiser, generator, epoch, history):
    save(torch, {"model": model.state_dict(), "optimiser": optimiser.state_dict(), "generator": generator.get_state(),
                 "epoch": epoch, "history": history}, checkpoint)


def save_figure(fig, path):
    tmp = path + ".tmp.png"
    fig.savefig(tmp)
    os.replace(tmp, path)
    print(f"curves -> {path}")


def add_run_flags(parser):
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--resume", action="store_true", help="continue from the checkpoint of a killed run")
    parser.add_argument("--stop-after", type=int, default=None, help="stop after this many epochs of this run (a time-limited "
                        "job), leaving the checkpoint for --resume")


def add_fit_flags(parser, epochs, lr):
    """fit's flags (and add_run_flags'), with the command's default epochs and learning rate."""
    parser.add_argument("--epochs", type=int, default=epochs)
    parser.add_argument("--batch", type=int, default=512)
    parser.add_argument("--lr", type=float, default=lr)
    parser.add_argument("--weight-decay", type=float, default=1e-4)
    parser.add_argument("--lr-decay", type=float, default=0.1, help="the learning rate falls by this factor over the run")
    add_run_flags(parser)


def scheduled_epochs(args, epoch, optimiser):
    """The epochs this run trains, from a resumed run's epoch to --epochs (or --stop-after more), each
    with its learning rate set first (falling by --lr-decay over the whole schedule): yields each
    epoch's number as it will be once trained (1-based)."""
    gamma = args.lr_decay ** (1.0 / max(args.epochs, 1))
    stop = args.epochs if args.stop_after is None else min(args.epochs, epoch + args.stop_after)
    for e in range(epoch, stop):
        for group in optimiser.param_groups:
            group["lr"] = args.lr * gamma ** e
        yield e + 1


def stopped_early(args, epoch, task):
    """Whether --stop-after ended the run before --epochs (said; --resume goes on)."""
    if epoch < args.epochs:
        print(f"{task}: stopped after epoch {epoch} (--stop-after); --resume goes on", flush=True)
    return epoch < args.epochs


def train_task(args, task, torch):
    data, assets, counts = build_dataset(args.data, task, args.stride, args.repeat)
    x = data["train"][0]
    print(f"{task}: {counts['train']} train / {counts['valid']} valid episodes, {len(x)} samples of {x.shape[1]} inputs", flush=True)
    return fit(args, task, torch, data, os.path.join(args.out, f"{task}.pt"), {"assets": assets, "repeat": args.repeat})


def fit(args, task, torch, data, path, start):
    """Trains a model on data ({"train": (inputs, labels), "valid": ...}) and saves it to path; start:
    a saved model to go on from (its weights, normaliser, size, assets and repeat), or only the
    assets and repeat of a new one (the normaliser of data's train rows, --width, --depth)."""
    checkpoint = path + ".checkpoint"
    x, y = data["train"]
    norm = Normaliser.of_state(start["norm"]) if "model" in start else Normaliser(x)
    width, depth = (start["width"], start["depth"]) if "model" in start else (args.width, args.depth)
    xt, xn, yt = torch.from_numpy(x), torch.from_numpy(norm(x)), torch.from_numpy(y)
    valid = None
    if "valid" in data:
        vx, vy = data["valid"]
        valid = (torch.from_numpy(norm(vx)), torch.from_numpy(vx), torch.from_numpy(vy))
    torch.manual_seed(args.seed)
    model = build_model(torch, x.shape[1], width, depth)
    if "model" in start:
        model.load_state_dict(start["model"])
    optimiser = torch.optim.AdamW(model.parameters(), lr=args.lr, weight_decay=args.weight_decay)
    epoch, history = 0, []
    generator = torch.Generator().manual_seed(args.seed)
    if args.resume and os.path.exists(checkpoint):
        epoch, history = resume(torch, checkpoint, model, optimiser, generator, task)
    t0 = time.perf_counter()
    for epoch in scheduled_epochs(args, epoch, optimiser):
        model.train()
        order = torch.randperm(len(xn), generator=generator)
        total = 0.0
        for begin in range(0, len(order), args.batch):
            idx = order[begin:begin + args.batch]
            loss = loss_of(torch, model(xn[idx]), xt[idx], yt[idx])
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
            total += loss.item() * len(idx)
        model.eval()
        with torch.no_grad():
            held_out = loss_of(torch, model(valid[0]), valid[1], valid[2]).item() if valid else None
        history.append((epoch, total / len(xn), held_out))
        shown = "none (no valid episodes)" if held_out is None else f"{held_out:.4f}"
        print(f"{task} epoch {epoch}/{args.epochs}: train loss {total / len(xn):.4f}, held-out loss {shown}, "
              f"{time.perf_counter() - t0:.0f} s", flush=True)
        write_checkpoint(torch, checkpoint, model, optimiser, generator, epoch, history)
    if stopped_early(args, epoch, task):
        return None
    save(torch, {"model": model.state_dict(), "inputs": x.shape[1], "width": width, "depth": depth, "norm": norm.state(),
                 "assets": start["assets"], "task": task, "history": history, "repeat": start["repeat"]}, path)
    print(f"{task}: model -> {path}", flush=True)
    return model


def train(args, train_one=None):
    """train_one(args, task, torch) (default: this module's train_task) for each of --tasks."""
    import torch
    torch.set_num_threads(args.threads)
    os.makedirs(args.out, exist_ok=True)
    return {task: (train_one or train_task)(args, task, torch) for task in args.tasks.split(",")}


# ---- acting (evaluate.py: python:manisoft.reference_policy:act)

def observed_features(obs, roles, memory, assets):
    """features() of an observation (evaluate.py's privileged one: end_effector, gripper_width,
    gripper_state, object_poses)."""
    ee, poses = np.asarray(obs["end_effector"]), np.asarray(obs["object_poses"])
    return features(roles, ee[:3, 3], ee[:3, :3], float(obs["gripper_width"]), float(obs["gripper_state"]), poses[:, :3, 3],
                    poses[:, :3, :3], memory, assets)


class Policy:
    """One task's model and its memory of the episode: its previous command, the end effector's
    position then, the control steps since the command was first sent. At each call it keeps the
    previous command unless the switch logit is positive; then it sends the predicted next one."""

    def __init__(self, path, torch):
        saved = torch.load(path)
        self.torch = torch
        self.model = build_model(torch, saved["inputs"], saved["width"], saved["depth"])
        self.model.load_state_dict(saved["model"])
        self.model.eval()
        self.norm = Normaliser.of_state(saved["norm"])
        self.assets = saved["assets"]
        self.repeat = saved["repeat"]
        self.reset()

    def reset(self):
        self.previous = self.position = None
        self.change = np.zeros(7)
        self.age = self.moves = 0

    def __call__(self, obs, roles):
        p = np.asarray(obs["end_effector"])[:3, 3]
        if self.previous is None:
            self.previous, self.position = home_command(p), p.copy()
        x = observed_features(obs, roles, (self.previous, self.change, p - self.position, self.age, self.moves), self.assets)
        torch = self.torch
        x = x.astype(np.float32)[None]
        with torch.no_grad():
            position, rotation, s, switch = decode(torch, self.model(torch.from_numpy(self.norm(x))), torch.from_numpy(x))
        if switch[0] > 0:
            action = np.empty(7)
            action[:3] = self.previous[:3] + position[0].numpy()
            action[3:6] = self.previous[3:6] + rotation[0].numpy()
            action[6] = 1.0 if s[0] > 0 else 0.0
            self.moves = 1 if action[6] != self.previous[6] else self.moves + 1
            self.previous, self.change, self.age = action, action - self.previous, 0
        self.position = p.copy()
        self.age += self.repeat
        return self.previous.copy()


_models = {}
_episode = {"scene": None, "roles": None}


def reset():
    """Called by evaluate.py at the start of every episode: forgets the previous command."""
    _episode["scene"] = None
    for m in _models.values():
        m.reset()


def act(obs):
    """The harness's python:manisoft.reference_policy:act (--observation privileged --action-mode
    ee_pose): the next end-effector target. The models are $MANISOFT_REFERENCE_MODELS/<TASK>.pt."""
    import torch
    if _episode["scene"] != obs["scene"]:
        _episode["scene"], _episode["roles"] = obs["scene"], SceneRoles(json.loads(obs["scene"]))
    task = _episode["roles"].task
    if task not in _models:
        directory = os.environ.get("MANISOFT_REFERENCE_MODELS")
        if not directory:
            raise RuntimeError("set MANISOFT_REFERENCE_MODELS to a directory written by reference_policy.py train")
        torch.set_num_threads(1)
        _models[task] = Policy(os.path.join(directory, f"{task}.pt"), torch)
    return _models[task](obs, _episode["roles"])


def curves(args):
    """The models' learning curves (train and held-out loss per epoch) in one picture."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import torch
    fig, ax = plt.subplots(figsize=(6.4, 4.0), dpi=120)
    for path in args.models:
        saved = torch.load(path)
        epochs, train_loss, held_out = zip(*saved["history"])
        name = os.path.basename(path)
        line, = ax.plot(epochs, train_loss, label=f"{name} train")
        if all(h is not None for h in held_out):
            ax.plot(epochs, held_out, "--", color=line.get_color(), label=f"{name} held-out (valid mask)")
    ax.set_xlabel("epoch")
    ax.set_ylabel("loss (log scale)")
    ax.set_yscale("log")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Reference policy (end-effector track): learning curves", fontsize=9)
    fig.tight_layout()
    save_figure(fig, args.out)


def main(argv=None):
    p = argparse.ArgumentParser(description="The privileged-state reference policy on the end-effector track: train, plot")
    sub = p.add_subparsers(dest="command", required=True)
    t = sub.add_parser("train", help="train one model per task on a generated dataset")
    t.add_argument("--data", required=True, action="append", help="a dataset directory written by generate_dataset (repeat for more)")
    t.add_argument("--out", required=True, help="directory for <TASK>.pt")
    t.add_argument("--tasks", default="ALN,COLL")
    add_fit_flags(t, epochs=30, lr=1e-3)
    t.add_argument("--width", type=int, default=256)
    t.add_argument("--depth", type=int, default=3)
    t.add_argument("--stride", type=int, default=2, help="a sample every this many control steps")
    t.add_argument("--repeat", type=int, default=36, help="control steps between the policy's commands")
    c = sub.add_parser("curves", help="plot the learning curves of trained models")
    c.add_argument("models", nargs="+", help="<TASK>.pt files")
    c.add_argument("--out", required=True, help="PNG file")
    args = p.parse_args(argv)
    (train if args.command == "train" else curves)(args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
