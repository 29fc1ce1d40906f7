#!/usr/bin/env python3
"""The reference policy from the image and the instruction on the end-effector track: a perception
network (a small CNN trained from scratch, the instruction embedded) reads off the camera image
what the privileged reference policy (reference_policy.py) reads from the state, and that policy's
model, trained further on what the perception reads (adapt), acts on it. It sees what the paper's
policies see, the image and the instruction, plus its own previous commands.

    generate_dataset --tasks ALN,COLL --clean 1000 --randomized 1000 --seed 1 --out data/ref2
    render_dataset data/ref2 --out img/ref2 --every 36 --image-size 384 384
    /usr/bin/python3 -m manisoft.image_policy train --data data/ref2:img/ref2 --tasks ALN,COLL --out img/models
    /usr/bin/python3 -m manisoft.image_policy refine --data data/ref2:img/ref2 --perception img/models --tasks ALN,COLL --out img/models
    /usr/bin/python3 -m manisoft.image_policy adapt --data data/ref2:img/ref2 --perception img/models --reference ref/models \\
        --tasks ALN,COLL --out img/models
    MANISOFT_PERCEPTION_MODELS=img/models /usr/bin/python3 -m manisoft.evaluate \\
        --task ALN --setting all --policy python:manisoft.image_policy:act --action-mode ee_pose --image-size 384 384 --out img/eval

Perception: the image's table region (CROP, fractions of the image) at 96 x 96 pixels with two
coordinate channels; four convolutions, the instruction's words (a bag of embeddings) scaling and
shifting the third one's channels (FiLM). The scene's points (the end effector, the moved object,
the goal's second pose: COLL's container, ALN's and OVR's marker; OVR's obstacle) are located by a
heat map each on the third one's 24 x 24 grid (the expected image coordinates under its softmax)
and placed where the camera ray through them meets a regressed height. An MLP over 64 free
keypoints of the same kind, the located points, the fourth convolution's mean and the instruction
embedding regresses the heights, the end effector's, the object's and the second pose's rotations
(first two columns), the finger width and the moved object's asset (a class). Trained on frames
rendered from the dataset's episodes (render_dataset --every K), the episode's recorded state the
labels: squared errors in units of FIELDS' (world) and of a crop pixel (the located points' image
coordinates), the cross-entropy of each point's heat map cell (the expected position alone leaves
a spread-out map stuck between candidates) and of the asset. Frames before the grasp, where the
moved object rests on the table, are drawn --rest-weight times as often. Each frame's instruction
is drawn from the episode's canonical and seen ones, a word dropped at random (unseen paraphrases
use words training never saw).
Refinement (refine; used where <TASK>.refine.pt lies beside <TASK>.perception.pt): the end effector,
the moved object and ALN's and OVR's marker are located again in PATCH x PATCH patches of the 384 x
384 image centred on the first stage's estimate (twice, the second centred on the first's answer):
a heat map on CELL-pixel cells, the height and the marker's heading regressed from the features at
the located point. While the policy has not closed the gripper the moved object rests on the
table, at the height of training's resting objects.
Acting: the static parts of the scene (the container or goal, the obstacle, the asset) are averaged
over the episode's frames so far (a refined marker: the median); the end effector, the fingers and the moved object are read from
the current frame, the end effector moved along its camera ray to the point nearest the last
command where that is within NEAR (the arm settles at its command; one view's height is the least
certain); S is the policy's own last command. The task is the one whose training instructions make
the instruction's words likeliest (naive Bayes over the words).
Adapting (adapt; used where <TASK>.head.pt lies beside <TASK>.perception.pt, else
$MANISOFT_REFERENCE_MODELS/<TASK>.pt acts): the privileged model trained further on rows whose
state is what perception reads off each rendered frame as when acting, the memory and labels the
expert's commands; the columns constant over the privileged rows pass their deviation unscaled.
"""
import argparse
import glob
import json
import os
import re
import sys
import time

import numpy as np

try:  # python3 -m manisoft.image_policy, or the script beside reference_policy.py
    from . import reference_policy as rp
except ImportError:
    import reference_policy as rp

CROP = (0.25, 0.28125, 0.75, 0.78125)  # left, top, right, bottom: the table and the space above it
SIZE = 96  # the crop's pixels a side
KEYPOINTS = 64
# the answer vector: (first column, length, unit of its error in the loss); a symmetric object's
# rotation is partly unobservable, hence its larger unit
FIELDS = {"ee_position": (0, 3, 0.01), "ee_rotation": (3, 6, 0.05), "width": (9, 1, 0.005),
          "object_position": (10, 3, 0.01), "object_rotation": (13, 6, 0.3),
          "second_position": (19, 3, 0.01), "second_rotation": (22, 6, 0.1), "obstacle": (28, 3, 0.01)}
ANSWER = 31
STATIC = ("second_position", "second_rotation", "obstacle")
POINTS = ("ee_position", "object_position", "second_position", "obstacle")  # located by keypoints
PIXEL = 2.0 / SIZE  # a crop pixel in the keypoints' coordinates (-1 to 1 across the crop)


def words(text):
    return re.findall(r"[a-z0-9']+", text.lower())


def crop(image):
    """The image's CROP region at SIZE x SIZE (uint8 H x W x 3 -> uint8 SIZE x SIZE x 3), by area
    averaging when the region is larger."""
    h, w = image.shape[:2]
    x0, y0, x1, y1 = (int(round(f * s)) for f, s in zip(CROP, (w, h, w, h)))
    region = image[y0:y1, x0:x1]
    if region.shape[:2] == (SIZE, SIZE):
        return np.ascontiguousarray(region)
    ry, rx = region.shape[0] / SIZE, region.shape[1] / SIZE
    if ry == int(ry) and rx == int(rx) and ry >= 1:
        r = region.reshape(SIZE, int(ry), SIZE, int(rx), 3).astype(np.float32).mean((1, 3))
        return np.round(r).astype(np.uint8)
    raise ValueError(f"image_policy: a {w} x {h} image's crop is {region.shape[1]} x {region.shape[0]}, "
                     f"not {SIZE} x {SIZE} or a whole multiple of it (use --image-size 192 192 or 384 384)")


# ---- the dataset: frames and their labels

def labels_of(scene, eef, grip, objects):
    """The answer vector of one recorded step (eef: 7, grip: 2, objects: k x 7) and the asset."""
    roles = rp.SceneRoles(scene)
    y = np.zeros(ANSWER)
    y[0:3], y[3:9], y[9] = eef[:3], rp.six(rp.rotation_of_quaternion(eef[3:])), grip[0]
    moved = objects[roles.roles[0]]
    y[10:13], y[13:19] = moved[:3], rp.six(rp.rotation_of_quaternion(moved[3:]))
    if scene["task"] == "COLL":
        c = objects[roles.roles[1]]
        y[19:22], y[22:28] = c[:3], rp.six(rp.rotation_of_quaternion(c[3:]))
    else:
        y[19:22], y[22:28] = roles.goal[0], rp.six(roles.goal[1])
    y[28:31] = roles.obstacle
    return y, roles.asset


class Camera:
    """The scene's camera (scene JSON "cameras"[0]): world points to the crop's coordinates (-1 to 1
    across, x right, y down) and back, onto a given height."""

    def __init__(self, spec):
        self.position = np.asarray(spec["position"], dtype=np.float64)
        forward = np.asarray(spec["look_at"], dtype=np.float64) - self.position
        self.forward = forward / np.linalg.norm(forward)
        right = np.cross(self.forward, np.asarray(spec["up"], dtype=np.float64))
        self.right = right / np.linalg.norm(right)
        self.up = np.cross(self.right, self.forward)
        self.tan = np.tan(np.radians(spec["fov_y_deg"]) / 2)
        self.aspect = spec["width"] / spec["height"]
        self.spec = {k: spec[k] for k in ("position", "look_at", "up", "fov_y_deg", "width", "height")}

    def to_crop(self, p):
        d = np.asarray(p, dtype=np.float64) - self.position
        depth = d @ self.forward
        ndc = np.array([(d @ self.right) / (depth * self.tan * self.aspect), (d @ self.up) / (depth * self.tan)])
        fraction = np.array([(ndc[0] + 1) / 2, (1 - ndc[1]) / 2])  # of the image's width and height
        return 2 * (fraction - [CROP[0], CROP[1]]) / [CROP[2] - CROP[0], CROP[3] - CROP[1]] - 1

    def rays(self, torch, uv):
        """Unit-free ray directions (N x K x 3) through crop coordinates uv (N x K x 2)."""
        fx = CROP[0] + (CROP[2] - CROP[0]) * (uv[..., 0] + 1) / 2
        fy = CROP[1] + (CROP[3] - CROP[1]) * (uv[..., 1] + 1) / 2
        ax, ay = (2 * fx - 1) * self.tan * self.aspect, (1 - 2 * fy) * self.tan
        basis = torch.tensor(np.stack([self.forward, self.right, self.up]), dtype=uv.dtype)
        return basis[0] + ax[..., None] * basis[1] + ay[..., None] * basis[2]

    def on_height(self, torch, uv, z):
        """The points (N x K x 3) on the rays through uv at heights z (N x K)."""
        d = self.rays(torch, uv)
        origin = torch.tensor(self.position, dtype=uv.dtype)
        return origin + ((z - origin[2]) / d[..., 2])[..., None] * d


def points_of(camera, y):
    """The crop coordinates (len(POINTS) x 2) of the answer's points."""
    return np.stack([camera.to_crop(y[FIELDS[name][0]:FIELDS[name][0] + 3]) for name in POINTS])


def rendered_episodes(pairs, task):
    """The task's rendered episodes, as (mask, scene, the recorded arrays (eef_pose, gripper,
    object_poses, ee_target), the frames, their control steps, the episode's instructions (the
    canonical one first, then the seen ones), camera)."""
    import h5py
    camera = None
    for pair in pairs:
        data, images = pair.split(":", 1)
        with h5py.File(os.path.join(data, "dataset.hdf5"), "r") as index:
            masks = {name: {m.decode() for m in index["mask"][name][()]} for name in ("train", "valid")}
            for path in sorted(glob.glob(os.path.join(images, "demo_*.hdf5"))):
                demo = os.path.basename(path)[:-len(".hdf5")]
                if demo not in index["data"]:
                    raise ValueError(f"{path}: {demo} is not in {data}/dataset.hdf5 (images of another dataset?)")
                g = index["data"][demo]
                if g.attrs["task"] != task:
                    continue
                with h5py.File(path, "r") as f:
                    frames = f["data"][demo]["images"]["agentview_image"][()]
                    steps = f["data"][demo]["images"]["agentview_image_steps"][()]
                scene = json.loads(g.attrs["scene"])
                if camera is None:
                    camera = Camera(scene["cameras"][0])
                elif Camera(scene["cameras"][0]).spec != camera.spec:
                    raise ValueError(f"{data}: {demo}'s camera differs from the other episodes' (the policy reads one view)")
                arrays = {k: g["obs"][k][()].astype(np.float64) for k in ("eef_pose", "gripper", "object_poses", "ee_target")}
                if len(steps) and steps.max() >= len(arrays["eef_pose"]):
                    raise ValueError(f"{path}: a frame at step {steps.max()}, but {data}'s {demo} has {len(arrays['eef_pose'])} "
                                     "steps (images of another dataset?)")
                said = [str(g.attrs["instruction"])] + json.loads(g.attrs["instructions_seen"])
                mask = "train" if demo in masks["train"] else "valid"
                yield mask, scene, arrays, frames, steps, said, camera


def episode_frames(pairs, task):
    """Every rendered frame of the task's episodes, as (mask, image, answer, asset, the episode's
    instructions, whether the moved object still rests (before the grasp), camera)."""
    for mask, scene, a, frames, steps, said, camera in rendered_episodes(pairs, task):
        eef, grip = a["eef_pose"], a["gripper"]
        obj = a["object_poses"].reshape(len(eef), -1, 7)
        closed = np.flatnonzero(grip[:, 1] >= 0.5)
        grasp = closed[0] if len(closed) else len(grip)  # the moved object rests on the table before
        for frame, step in zip(frames, steps):
            y, asset = labels_of(scene, eef[step], grip[step], obj[step])
            yield mask, frame, y, asset, said, step < grasp, camera


def read_frames(pairs, task):
    """Every rendered frame of the task's episodes: per mask (train, valid) the crops (N x SIZE x
    SIZE x 3 uint8), the answers (N x ANSWER), the located points' crop coordinates, the assets,
    the episode's instructions and whether the moved object still rests (before the grasp)."""
    out = {m: {"images": [], "answers": [], "points": [], "assets": [], "instructions": [], "resting": []} for m in ("train", "valid")}
    out["camera"] = None
    for mask, frame, y, asset, said, resting, camera in episode_frames(pairs, task):
        out["camera"] = camera
        m = out[mask]
        m["images"].append(crop(frame))
        m["answers"].append(y)
        m["points"].append(points_of(camera, y))
        m["assets"].append(asset)
        m["instructions"].append(said)
        m["resting"].append(resting)
    return out


# ---- the network

REGRESSED = [FIELDS["ee_position"][0] + 2, FIELDS["object_position"][0] + 2, FIELDS["second_position"][0] + 2,
             FIELDS["obstacle"][0] + 2] + [c + i for name in ("ee_rotation", "width", "object_rotation", "second_rotation")
                                              for c, n, _ in [FIELDS[name]] for i in range(n)]  # heights, then the rest


def build_model(torch, vocabulary, assets, camera):
    nn = torch.nn

    class Perception(nn.Module):
        def __init__(self):
            super().__init__()
            self.c1, self.c2 = nn.Conv2d(5, 16, 5, 2, 2), nn.Conv2d(16, 32, 3, 2, 1)
            self.n1, self.n2 = nn.BatchNorm2d(16), nn.BatchNorm2d(32)
            self.c3, self.c4 = nn.Conv2d(32, KEYPOINTS, 3, 1, 1), nn.Conv2d(KEYPOINTS, 64, 3, 2, 1)
            self.sharpness = nn.Parameter(torch.full((1, KEYPOINTS, 1), 5.0))  # the spatial softmax's inverse temperature
            self.words = nn.EmbeddingBag(vocabulary + 1, 32, mode="mean")  # index 0: a word training never saw
            self.film = nn.Linear(32, 2 * KEYPOINTS)
            self.located = nn.Conv2d(KEYPOINTS, len(POINTS), 1)  # a heat map per located point
            self.head = nn.Sequential(nn.Linear(2 * KEYPOINTS + 2 * len(POINTS) + 64 + 32, 256), nn.ReLU(), nn.Linear(256, 256),
                                      nn.ReLU(), nn.Linear(256, len(REGRESSED) + assets))
            grid = torch.linspace(-1.0, 1.0, SIZE)
            self.register_buffer("coords", torch.stack(torch.meshgrid(grid, grid, indexing="ij"))[None])
            self.register_buffer("mean", torch.zeros(len(REGRESSED)))
            self.register_buffer("spread", torch.ones(len(REGRESSED)))
            half = (torch.arange(SIZE // 4, dtype=torch.float32) * 4 + 2) * PIXEL - 1  # the cells' centres
            self.register_buffer("kx", half[None, None, None, :].expand(1, 1, SIZE // 4, SIZE // 4).reshape(1, 1, -1))
            self.register_buffer("ky", half[None, None, :, None].expand(1, 1, SIZE // 4, SIZE // 4).reshape(1, 1, -1))

        def forward(self, images, tokens, offsets, heat_maps=False):
            """images: N x SIZE x SIZE x 3 uint8; tokens, offsets: the instructions' word indices.
            heat_maps: also return the located points' heat map logits (N x len(POINTS) x cells)."""
            x = images.permute(0, 3, 1, 2).float() / 255.0
            x = torch.cat([x, self.coords.expand(len(x), -1, -1, -1)], 1).contiguous(memory_format=torch.channels_last)
            x = torch.relu(self.n2(self.c2(torch.relu(self.n1(self.c1(x))))))
            e = self.words(tokens, offsets)
            scale, shift = self.film(e).chunk(2, 1)
            k = self.c3(x) * (1 + scale[:, :, None, None]) + shift[:, :, None, None]
            soft = torch.softmax(k.flatten(2) * self.sharpness, 2)
            points = torch.cat([(soft * self.kx).sum(2), (soft * self.ky).sum(2)], 1)
            logits = self.located(k).flatten(2)
            heat = torch.softmax(logits, 2)
            uv = torch.stack([(heat * self.kx).sum(2), (heat * self.ky).sum(2)], 2)  # N x len(POINTS) x 2
            pooled = torch.relu(self.c4(torch.relu(k))).mean((2, 3))
            out = self.head(torch.cat([points, uv.flatten(1), pooled, e], 1))
            # the regressed values as the training labels' mean plus their spread times the output
            regressed = self.mean + self.spread * out[:, :len(REGRESSED)]
            answer = torch.zeros(len(x), ANSWER, dtype=x.dtype)
            answer[:, REGRESSED] = regressed
            where = camera.on_height(torch, uv, regressed[:, :len(POINTS)])
            for i, name in enumerate(POINTS):
                answer[:, FIELDS[name][0]:FIELDS[name][0] + 3] = where[:, i]
            out = torch.cat([answer, uv.flatten(1), out[:, len(REGRESSED):]], 1)
            return (out, logits) if heat_maps else out

    return Perception()


def encode(torch, texts, vocabulary, drop=0.0, generator=None):
    """Word indices (0 for unknown or dropped words) and offsets for EmbeddingBag."""
    tokens, offsets = [], []
    for text in texts:
        offsets.append(len(tokens))
        ids = [vocabulary.get(w, 0) for w in words(text)] or [0]
        if drop > 0:
            keep = torch.rand(len(ids), generator=generator).numpy() >= drop
            ids = [i if k else 0 for i, k in zip(ids, keep)]
        tokens.extend(ids)
    return torch.tensor(tokens, dtype=torch.long), torch.tensor(offsets, dtype=torch.long)


HEAD = ANSWER + 2 * len(POINTS)  # the answer, the located points' crop coordinates, then the asset logits


def cells_of(torch, points):
    """The heat map cell (row-major on the SIZE / 4 grid) holding each point (N x 2 len(POINTS)), -100
    (ignored) for a point outside the crop."""
    uv = points.reshape(len(points), -1, 2)
    cell = torch.floor((uv + 1) / PIXEL / 4).long()
    inside = ((cell >= 0) & (cell < SIZE // 4)).all(2)
    return torch.where(inside, cell[..., 1] * (SIZE // 4) + cell[..., 0], torch.full_like(cell[..., 0], -100))


def loss_of(torch, out, answers, points, asset_ids, scales, heat=None):
    """Squared errors of the answer in units of FIELDS', of the located points in crop pixels, the
    asset's cross-entropy and, given the heat map logits, each point's cell's cross-entropy (the
    expected position alone leaves a spread-out heat map stuck between candidates). scales: 1 / unit
    per column, 0 where the task has no such thing."""
    squared = ((out[:, :ANSWER] - answers) * scales[:ANSWER]) ** 2
    located = ((out[:, ANSWER:HEAD] - points) * scales[ANSWER:]) ** 2
    loss = squared.mean() + located.mean() + torch.nn.functional.cross_entropy(out[:, HEAD:], asset_ids)
    if heat is not None:
        cells = cells_of(torch, points)
        active = scales[ANSWER::2] > 0
        loss = loss + torch.nn.functional.cross_entropy(heat[:, active].flatten(0, 1), cells[:, active].flatten(), ignore_index=-100)
    return loss


def errors_of(torch, out, answers):
    """Mean error per field: the distance for positions (m), the mean absolute error otherwise."""
    def error(c, n):
        d = out[:, c:c + n] - answers[:, c:c + n]
        return float(d.norm(dim=1).mean() if n == 3 else d.abs().mean())
    return {name: error(c, n) for name, (c, n, _) in FIELDS.items()}


def scales_of(torch, task):
    s = np.zeros(HEAD, dtype=np.float32)
    for name, (c, n, unit) in FIELDS.items():
        s[c:c + n] = 0.0 if name == "obstacle" and task != "OVR" else 1.0 / unit
    s[ANSWER:] = 1.0 / PIXEL
    if task != "OVR":
        s[HEAD - 2:HEAD] = 0.0
    return torch.from_numpy(s)


def train_task(args, task, torch):
    path = os.path.join(args.out, f"{task}.perception.pt")
    checkpoint = path + ".checkpoint"
    data = read_frames(args.data, task)
    train, valid = data["train"], data["valid"]
    if not train["images"]:
        raise ValueError(f"{', '.join(args.data)}: no rendered {task} frames of train-mask episodes")
    assets = sorted(set(train["assets"]))
    counts = {}
    for said in train["instructions"]:
        for text in said:
            for w in words(text):
                counts[w] = counts.get(w, 0) + 1
    vocabulary = {w: i + 1 for i, w in enumerate(sorted(counts))}
    images = torch.from_numpy(np.stack(train["images"]))
    answers = torch.from_numpy(np.asarray(train["answers"], dtype=np.float32))
    points = torch.from_numpy(np.asarray(train["points"], dtype=np.float32).reshape(len(answers), -1))
    asset_ids = torch.tensor([assets.index(a) for a in train["assets"]])
    weights = torch.tensor([args.rest_weight if r else 1.0 for r in train["resting"]], dtype=torch.float64)
    scales = scales_of(torch, task)
    torch.manual_seed(args.seed)
    model = build_model(torch, len(vocabulary), len(assets), data["camera"])
    model.mean.copy_(answers[:, REGRESSED].mean(0))
    model.spread.copy_(answers[:, REGRESSED].std(0).clamp(min=1e-3))
    optimiser = torch.optim.AdamW(model.parameters(), lr=args.lr, weight_decay=1e-4)
    generator = torch.Generator().manual_seed(args.seed)
    epoch, history = 0, []
    if args.resume and os.path.exists(checkpoint):
        epoch, history = rp.resume(torch, checkpoint, model, optimiser, generator, task)
    print(f"{task}: {len(images)} train / {len(valid['images'])} valid frames, {len(assets)} assets, "
          f"{len(vocabulary)} words", flush=True)

    def valid_pass():
        if not valid["images"]:
            return None, {}
        vi, va = np.stack(valid["images"]), torch.from_numpy(np.asarray(valid["answers"], dtype=np.float32))
        vp = torch.from_numpy(np.asarray(valid["points"], dtype=np.float32).reshape(len(va), -1))
        vid = torch.tensor([assets.index(a) if a in assets else 0 for a in valid["assets"]])
        outs = []
        with torch.no_grad():
            for s in range(0, len(vi), 512):
                tokens, offsets = encode(torch, [said[0] for said in valid["instructions"][s:s + 512]], vocabulary)
                outs.append(model(torch.from_numpy(vi[s:s + 512]), tokens, offsets))
        out = torch.cat(outs)
        errors = errors_of(torch, out, va)
        if task != "OVR":
            del errors["obstacle"]
        errors["asset_accuracy"] = float((out[:, HEAD:].argmax(1) == vid).float().mean())
        return loss_of(torch, out, va, vp, vid, scales).item(), errors

    t0 = time.perf_counter()
    for epoch in rp.scheduled_epochs(args, epoch, optimiser):
        model.train()
        # frames of the object at rest drawn --rest-weight times as often: the moved object is held
        # for most of an episode, and a network that follows the hand is wrong only before the grasp
        order = torch.multinomial(weights, len(images), replacement=True, generator=generator)
        total = 0.0
        for start in range(0, len(order), args.batch):
            idx = order[start:start + args.batch]
            pick = torch.randint(0, 1 << 30, (len(idx),), generator=generator)
            texts = [train["instructions"][i][p % len(train["instructions"][i])] for i, p in zip(idx.tolist(), pick.tolist())]
            tokens, offsets = encode(torch, texts, vocabulary, args.word_drop, generator)
            out, heat = model(images[idx], tokens, offsets, heat_maps=True)
            loss = loss_of(torch, out, answers[idx], points[idx], asset_ids[idx], scales, heat)
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
            total += loss.item() * len(idx)
        model.eval()
        held_out, errors = valid_pass()
        history.append((epoch, total / len(images), held_out, errors))
        shown = "" if held_out is None else f", held-out loss {held_out:.3f} (" + ", ".join(
            f"{k} {v * (100 if k.endswith(('position', 'width', 'obstacle')) else 1):.2f}" for k, v in errors.items()) + ")"
        print(f"{task} epoch {epoch}/{args.epochs}: train loss {total / len(images):.3f}{shown}, "
              f"{time.perf_counter() - t0:.0f} s", flush=True)
        rp.write_checkpoint(torch, checkpoint, model, optimiser, generator, epoch, history)
    if rp.stopped_early(args, epoch, task):
        return None
    rp.save(torch, {"model": model.state_dict(), "vocabulary": vocabulary, "assets": assets, "task": task, "history": history,
                    "word_counts": counts, "camera": data["camera"].spec}, path)
    print(f"{task}: model -> {path}", flush=True)
    return model


def train(args, train_one=None):
    for pair in args.data:
        if ":" not in pair:
            raise SystemExit(f"image_policy: --data {pair}: expected DATASET_DIR:IMAGES_DIR")
    return rp.train(args, train_one or train_task)


# ---- refinement: the end effector and the moved object located again at full resolution

FINE = 2 * SIZE  # the crop's pixels a side at the resolution refinement reads (a 384 x 384 image)
PATCH, WINDOW = 48, 88  # a refinement patch; the window kept around a training point (the patch shifts up to 20 pixels)
CELL = 2  # the refinement heat map's cell, fine pixels
PASSES = 2  # patches centred first on the first stage's estimate, then on the previous pass's
HEADED = "second_position"  # ALN's and OVR's marker: its heading is read off the patch too (the marker is upright)


def refined_points(task):
    """The points a task's refinement locates again: the end effector and the moved object; ALN's
    and OVR's marker (COLL's container is large in the first stage's crop)."""
    return ("ee_position", "object_position") + (() if task == "COLL" else (HEADED,))


def fine_of(uv):
    """Crop coordinates (-1 to 1 across) to fine crop pixels (pixel i spans [i, i + 1))."""
    return (np.asarray(uv, dtype=np.float64) + 1) / 2 * FINE


def window(image, centre, size):
    """The size x size pixels of the image around centre (fine crop pixels), zeros off the image, and
    their corner (integer fine crop pixels). The image's crop must be FINE pixels a side."""
    h, w = image.shape[:2]
    x0, y0, x1, y1 = (int(round(f * s)) for f, s in zip(CROP, (w, h, w, h)))
    if (x1 - x0, y1 - y0) != (FINE, FINE):
        raise ValueError(f"image_policy: refinement reads the crop at {FINE} x {FINE} pixels; a {w} x {h} image's is "
                         f"{x1 - x0} x {y1 - y0} (use --image-size {2 * FINE} {2 * FINE})")
    corner = np.floor(np.clip(centre, -FINE, 2 * FINE) - size / 2).astype(int)  # the image and around it
    out = np.zeros((size, size, 3), dtype=np.uint8)
    gx, gy = corner[0] + x0, corner[1] + y0
    ax, ay, bx, by = max(gx, 0), max(gy, 0), min(gx + size, w), min(gy + size, h)
    if ax < bx and ay < by:
        out[ay - gy:by - gy, ax - gx:bx - gx] = image[ay:by, ax:bx]
    return out, corner


def build_refiner(torch, vocabulary, points):
    nn = torch.nn
    cells = PATCH // CELL

    class Refiner(nn.Module):
        """A patch (PATCH x PATCH fine pixels) and which point to find in it -> the point's position in
        the patch (the expectation under a heat map on CELL-pixel cells), its height and the heat map's
        logits. Dilated convolutions see the whole patch; the instruction and the point's kind scale
        and shift the third one's channels (FiLM); the height is regressed from the features at the
        located point, and so is the marker's heading (its cosine and sine) where points hold it."""

        def __init__(self):
            super().__init__()
            self.c1, self.n1 = nn.Conv2d(3, 32, 5, 2, 2), nn.BatchNorm2d(32)
            self.c2, self.n2 = nn.Conv2d(32, 48, 3, 1, 1), nn.BatchNorm2d(48)
            self.c3, self.n3 = nn.Conv2d(48, 48, 3, 1, 2, dilation=2), nn.BatchNorm2d(48)
            self.c4, self.n4 = nn.Conv2d(48, 48, 3, 1, 4, dilation=4), nn.BatchNorm2d(48)
            self.words = nn.EmbeddingBag(vocabulary + 1, 32, mode="mean")
            self.points = points
            self.kinds = nn.Embedding(len(points), 32)
            self.film = nn.Linear(32, 96)
            self.located = nn.Conv2d(48, 1, 1)
            self.height = nn.Sequential(nn.Linear(48 + 32, 64), nn.ReLU(), nn.Linear(64, 1))
            self.register_buffer("mean", torch.zeros(len(points)))
            self.register_buffer("spread", torch.ones(len(points)))
            centres = torch.arange(cells, dtype=torch.float32) * CELL + CELL / 2
            self.register_buffer("cx", centres.repeat(cells))  # row-major cells: x the column's centre
            self.register_buffer("cy", centres.repeat_interleave(cells))
            self.heading = nn.Sequential(nn.Linear(48 + 32, 64), nn.ReLU(), nn.Linear(64, 2)) if HEADED in points else None

        def forward(self, patches, kinds, tokens, offsets):
            x = (patches.permute(0, 3, 1, 2).float() / 255.0).contiguous(memory_format=torch.channels_last)
            x = torch.relu(self.n2(self.c2(torch.relu(self.n1(self.c1(x))))))
            e = self.words(tokens, offsets) + self.kinds(kinds)
            scale, shift = self.film(e).chunk(2, 1)
            x = torch.relu(self.n3(self.c3(x)) * (1 + scale[:, :, None, None]) + shift[:, :, None, None])
            x = torch.relu(self.n4(self.c4(x)))
            logits = self.located(x).flatten(1)
            heat = torch.softmax(logits, 1)
            where = torch.stack([(heat * self.cx).sum(1), (heat * self.cy).sum(1)], 1)
            at = (x.flatten(2) * heat[:, None]).sum(2)
            features = torch.cat([at, e], 1)
            z = self.mean[kinds] + self.spread[kinds] * self.height(features)[:, 0]
            heading = None if self.heading is None else self.heading(features)
            return where, z, logits, heading

    return Refiner()


def refine(torch, refiner, images, uv, tokens, offsets):
    """The refiner's points of each image located again: images (N full images), uv (N x k x 2) the
    first stage's crop coordinates, the instructions' word indices -> crop coordinates, heights
    (N x k) and the marker's heading (N angles, None without a marker)."""
    n, k = len(images), len(refiner.points)
    centre = fine_of(uv)
    kinds = torch.arange(k).repeat(n)
    index = torch.arange(n).repeat_interleave(k)
    tokens, offsets = bag_rows(torch, tokens, offsets, index)
    with torch.no_grad():
        for _ in range(PASSES):
            cut = [window(images[i], centre[i, j], PATCH) for i in range(n) for j in range(k)]
            where, z, _, heading = refiner(torch.from_numpy(np.stack([c[0] for c in cut])), kinds, tokens, offsets)
            centre = (np.stack([c[1] for c in cut]) + where.numpy().astype(np.float64)).reshape(n, k, 2)
    if heading is not None:
        heading = heading.numpy().astype(np.float64).reshape(n, k, 2)[:, refiner.points.index(HEADED)]
        heading = np.arctan2(heading[:, 1], heading[:, 0])
    return 2 * centre / FINE - 1, z.numpy().astype(np.float64).reshape(n, k), heading


def bag_rows(torch, tokens, offsets, index):
    """EmbeddingBag inputs repeating the bags at index."""
    ends = torch.cat([offsets[1:], torch.tensor([len(tokens)])])
    rows = [tokens[offsets[i]:ends[i]] for i in index.tolist()]
    return torch.cat(rows), torch.tensor(np.cumsum([0] + [len(r) for r in rows[:-1]]), dtype=torch.long)


def heading_of(six_columns):
    """The heading (rotation about z) of a rotation given by its first two columns."""
    return np.arctan2(six_columns[1], six_columns[0])


def read_windows(pairs, task, rest_weight, valid_every):
    """The train mask's windows (WINDOW pixels a side) around each frame's refined points with their
    corners, the points' fine crop pixels, heights and headings, and every valid_every-th valid frame whole."""
    train = {"windows": [], "corners": [], "targets": [], "heights": [], "kinds": [], "weights": [], "instructions": [],
             "resting": [], "headings": []}
    valid = {"images": [], "answers": [], "instructions": [], "resting": []}
    camera, seen = None, 0
    for mask, frame, y, _, said, resting, camera in episode_frames(pairs, task):
        if mask == "valid":
            seen += 1
            if seen % valid_every == 0:
                valid["images"].append(frame)
                valid["answers"].append(y)
                valid["instructions"].append(said[0])
                valid["resting"].append(resting)
            continue
        for kind, name in enumerate(refined_points(task)):
            p = y[FIELDS[name][0]:FIELDS[name][0] + 3]
            target = fine_of(camera.to_crop(p))
            cut, corner = window(frame, target, WINDOW)
            train["windows"].append(cut)
            train["corners"].append(corner)
            train["targets"].append(target)
            train["heights"].append(p[2])
            train["kinds"].append(kind)
            train["weights"].append(rest_weight if name == "object_position" and resting else 1.0)
            train["resting"].append(name == "object_position" and resting)
            train["headings"].append(heading_of(y[FIELDS["second_rotation"][0]:]))
            train["instructions"].append(said)
    return train, valid, camera


def refined_errors(torch, first, refiner, valid, rest_height):
    """Held-out errors, by the first stage alone and refined, (median, mean) each: the positions (m)
    of the end effector (every frame), the moved object (every frame and at rest) and the marker,
    and the marker's heading (rad). A resting object is placed at rest_height, as when acting."""
    camera, n, points = first.model_camera, len(valid["images"]), refiner.points
    answers = np.asarray(valid["answers"])
    resting = np.asarray(valid["resting"], dtype=bool)
    stage, fine, headings = [], [], []
    for s in range(0, n, 256):
        images = valid["images"][s:s + 256]
        tokens, offsets = encode(torch, valid["instructions"][s:s + 256], first.vocabulary)
        with torch.no_grad():
            out = first.model(torch.from_numpy(np.stack([crop(i) for i in images])), tokens, offsets).numpy().astype(np.float64)
        stage.append(out)
        uv = np.stack([out[:, ANSWER + 2 * POINTS.index(name):ANSWER + 2 * POINTS.index(name) + 2] for name in points], 1)
        uv, z, heading = refine(torch, refiner, images, uv, tokens, offsets)
        z[resting[s:s + 256], points.index("object_position")] = rest_height
        fine.append(camera.on_height(torch, torch.from_numpy(uv), torch.from_numpy(z)).numpy())
        headings.append(heading)
    stage, fine = np.concatenate(stage), np.concatenate(fine)
    errors = {}
    if HEADED in points:
        c = FIELDS["second_rotation"][0]
        truth = heading_of(answers[:, c:c + 2].T)
        a = np.abs(np.angle(np.exp(1j * (heading_of(stage[:, c:c + 2].T) - truth))))
        b = np.abs(np.angle(np.exp(1j * (np.concatenate(headings) - truth))))
        errors["marker heading"] = {"first stage": (float(np.median(a)), float(a.mean())), "refined": (float(np.median(b)), float(b.mean()))}
    for kind, name in enumerate(points):
        c = FIELDS[name][0]
        for label, rows in (("", np.ones(n, dtype=bool)), (" at rest", resting)):
            if name != "object_position" and label:
                continue
            a = np.linalg.norm(stage[rows, c:c + 3] - answers[rows, c:c + 3], axis=1)
            b = np.linalg.norm(fine[rows, kind] - answers[rows, c:c + 3], axis=1)
            errors[name + label] = {"first stage": (float(np.median(a)), float(a.mean())),
                                    "refined": (float(np.median(b)), float(b.mean()))}
    return errors


def refine_task(args, task, torch):
    path = os.path.join(args.out, f"{task}.refine.pt")
    checkpoint = path + ".checkpoint"
    first = Perception(os.path.join(args.perception, f"{task}.perception.pt"), torch)
    train, valid, camera = read_windows(args.data, task, args.rest_weight, args.valid_every)
    if not train["windows"]:
        raise ValueError(f"{', '.join(args.data)}: no rendered {task} frames of train-mask episodes")
    if camera.spec != first.model_camera.spec:
        raise ValueError(f"{args.perception}/{task}.perception.pt: trained for another camera than {', '.join(args.data)}'s")
    windows = torch.from_numpy(np.stack(train["windows"]))
    corners = np.asarray(train["corners"], dtype=np.float64)
    targets = np.asarray(train["targets"], dtype=np.float64)
    heights = torch.tensor(train["heights"], dtype=torch.float32)
    kinds = torch.tensor(train["kinds"])
    weights = torch.tensor(train["weights"], dtype=torch.float64)
    rest = heights[torch.tensor([bool(r) for r in train["resting"]])]
    rest_height = float(rest.mean()) if len(rest) else float(heights[kinds == 1].mean())  # the table's top
    torch.manual_seed(args.seed)
    points = refined_points(task)
    model = build_refiner(torch, len(first.vocabulary), points)
    headings = torch.tensor(np.stack([np.cos(train["headings"]), np.sin(train["headings"])], 1), dtype=torch.float32)
    headed = kinds == points.index(HEADED) if HEADED in points else torch.zeros(len(kinds), dtype=torch.bool)
    for kind in range(len(points)):
        model.mean[kind], model.spread[kind] = heights[kinds == kind].mean(), heights[kinds == kind].std().clamp(min=1e-3)
    optimiser = torch.optim.AdamW(model.parameters(), lr=args.lr, weight_decay=1e-4)
    generator = torch.Generator().manual_seed(args.seed)
    epoch, history = 0, []
    if args.resume and os.path.exists(checkpoint):
        epoch, history = rp.resume(torch, checkpoint, model, optimiser, generator, task)
    print(f"{task}: {len(windows)} train points / {len(valid['images'])} valid frames", flush=True)
    t0 = time.perf_counter()
    span = torch.arange(PATCH)
    for epoch in rp.scheduled_epochs(args, epoch, optimiser):
        model.train()
        order = torch.multinomial(weights, len(windows), replacement=True, generator=generator)
        total = 0.0
        for start in range(0, len(order), args.batch):
            idx = order[start:start + args.batch]
            shift = torch.randint(0, WINDOW - PATCH + 1, (len(idx), 2), generator=generator)
            pick = torch.randint(0, 1 << 30, (len(idx),), generator=generator)
            rows = (shift[:, 1, None] + span)[:, :, None]
            cols = (shift[:, 0, None] + span)[:, None, :]
            patches = windows[idx[:, None, None], rows, cols]
            goal = torch.from_numpy((targets[idx] - corners[idx]).astype(np.float32)) - shift
            texts = [train["instructions"][i][p % len(train["instructions"][i])] for i, p in zip(idx.tolist(), pick.tolist())]
            tokens, offsets = encode(torch, texts, first.vocabulary, args.word_drop, generator)
            where, z, logits, heading = model(patches, kinds[idx], tokens, offsets)
            cell = torch.floor(goal / CELL).long().clamp(0, PATCH // CELL - 1)
            loss = (torch.nn.functional.cross_entropy(logits, cell[:, 1] * (PATCH // CELL) + cell[:, 0])
                    + (((where - goal) / CELL) ** 2).sum(1).mean() + (((z - heights[idx]) / 0.01) ** 2).mean())
            if heading is not None:  # the heading's cosine and sine, in units of 0.1
                loss = loss + (headed[idx, None] * ((heading - headings[idx]) / 0.1) ** 2).sum(1).mean()
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
            total += loss.item() * len(idx)
        model.eval()
        errors = refined_errors(torch, first, model, valid, rest_height) if valid["images"] else {}
        history.append((epoch, total / len(windows), None, errors))
        shown = "".join(f"; {name} {e['first stage'][0] * u:.1f} -> {e['refined'][0] * u:.1f} {unit} median "
                        f"({e['first stage'][1] * u:.1f} -> {e['refined'][1] * u:.1f} mean)" for name, e in errors.items()
                        for u, unit in [(180 / np.pi, "deg") if name == "marker heading" else (100, "cm")])
        print(f"{task} refine epoch {epoch}/{args.epochs}: train loss {total / len(windows):.3f}{shown}, "
              f"{time.perf_counter() - t0:.0f} s", flush=True)
        rp.write_checkpoint(torch, checkpoint, model, optimiser, generator, epoch, history)
    if rp.stopped_early(args, epoch, task):
        return None
    rp.save(torch, {"model": model.state_dict(), "vocabulary": first.vocabulary, "task": task, "history": history,
                    "camera": camera.spec, "points": points, "rest_height": rest_height}, path)
    print(f"{task}: refinement -> {path}", flush=True)
    return model


def train_refiners(args):
    return train(args, refine_task)


def perceived_reads(pairs, task, perception, repeat, settings=("clean", "randomized")):
    """Perception.read of each rendered episode of the task in one of the settings: (mask, the
    recorded arrays, the frames' control steps, the episode's canonical instruction, read's rows)."""
    for mask, scene, a, frames, steps, said, _ in rendered_episodes(pairs, task):
        if scene["setting"] not in settings:
            continue
        if len(steps) and (steps[0] != 0 or np.any(np.diff(steps) != repeat)):
            raise ValueError(f"{task} frames at steps {', '.join(map(str, steps[:3]))}, ...: the head acts every {repeat} "
                             f"control steps from step 0; render with render_dataset --every {repeat}")
        yield mask, a, steps, said[0], perception.read(frames, said[0])


def perceived_rows(reads, perception, head):
    """The head's training rows with the state perception read off each rendered frame (reads:
    perceived_reads'), as when acting: an episode's frames folded in order, the moved object resting
    until the expert's command closes the gripper, seen_observation with the expert's previous
    command; the memory and the labels from the expert's commands (reference_policy.command_rows).
    {"train": (inputs, labels), "valid": ...} and the episodes of each mask."""
    split, counts = {"train": ([], []), "valid": ([], [])}, {"train": 0, "valid": 0}
    for mask, a, steps, _, (out, refined) in reads:
        perception.reset()
        counts[mask] += 1
        closed, last = False, None
        for i, (_, previous, change, _, age, count, label) in enumerate(rp.command_rows(a, steps, head["repeat"])):
            s = float(previous[6] >= 0.5)
            closed = closed or s > 0
            y, asset = perception.fold(out[i], frame_of(refined, i), not closed)
            seen, roles = seen_observation(perception, y, asset, s, previous if i else None)
            ee = seen["end_effector"][:3, 3]
            moved = np.zeros(3) if last is None else ee - last
            split[mask][0].append(rp.observed_features(seen, roles, (previous, change, moved, age, count), head["assets"]))
            split[mask][1].append(label)
            last = ee
    return {m: (np.asarray(x, dtype=np.float32), np.asarray(y, dtype=np.float32)) for m, (x, y) in split.items() if x}, counts


def adapt_task(args, task, torch):
    head = torch.load(os.path.join(args.reference, f"{task}.pt"))
    head["norm"] = rp.Normaliser.of_state(head["norm"]).constant_in_own_units().state()
    perception = Perception(os.path.join(args.perception, f"{task}.perception.pt"), torch)
    t0 = time.perf_counter()
    settings = ("clean", "randomized") if args.setting == "all" else (args.setting,)
    data, counts = perceived_rows(perceived_reads(args.data, task, perception, head["repeat"], settings), perception, head)
    if "train" not in data:
        raise ValueError(f"{', '.join(args.data)}: no rendered {task} frames of train-mask episodes ({args.setting} scenes)")
    print(f"{task}: {counts['train']} train / {counts['valid']} valid episodes, {len(data['train'][0])} train frames read "
          f"in {time.perf_counter() - t0:.0f} s", flush=True)
    return rp.fit(args, task, torch, data, os.path.join(args.out, f"{task}.head.pt"), head)


def adapt_heads(args):
    return train(args, adapt_task)


# ---- acting (evaluate.py: python:manisoft.image_policy:act)

class Perception:
    """One task's perception model and the episode's running estimates of the static parts."""

    def __init__(self, path, torch):
        saved = torch.load(path)
        self.torch, self.task = torch, saved["task"]
        self.vocabulary, self.assets, self.counts = saved["vocabulary"], saved["assets"], saved["word_counts"]
        self.model_camera = Camera(saved["camera"])
        self.model = build_model(torch, len(self.vocabulary), len(self.assets), self.model_camera)
        self.model.load_state_dict(saved["model"])
        self.model.eval()
        self.refiner = None
        refined = path[:-len(".perception.pt")] + ".refine.pt"
        if os.path.exists(refined):
            saved = torch.load(refined)
            if saved["camera"] != self.model_camera.spec or saved["vocabulary"] != self.vocabulary:
                raise ValueError(f"{refined}: trained beside another perception model than {path}")
            self.refiner = build_refiner(torch, len(self.vocabulary), tuple(saved["points"]))
            self.refiner.load_state_dict(saved["model"])
            self.refiner.eval()
            self.rest_height = saved["rest_height"]
        self.reset()

    def reset(self):
        self.static, self.asset_logits, self.frames = np.zeros(ANSWER), np.zeros(len(self.assets)), 0
        self.markers = []  # the refined marker's position and heading in each frame so far

    def read(self, images, instruction):
        """Both stages' networks on the images (frames of one episode, batched): the first stage's rows
        (N x HEAD) and, with a refinement, the refined points' positions (N x k x 3), the moved
        object's on its ray at the resting height (N x 3) and the marker's headings (N, or None)."""
        torch = self.torch
        images = [np.asarray(i) for i in images]
        tokens, offsets = encode(torch, [instruction] * len(images), self.vocabulary)
        with torch.no_grad():
            out = self.model(torch.from_numpy(np.stack([crop(i) for i in images])), tokens, offsets).numpy().astype(np.float64)
        if self.refiner is None:
            return out, None
        points = self.refiner.points
        uv = np.stack([out[:, ANSWER + 2 * POINTS.index(name):ANSWER + 2 * POINTS.index(name) + 2] for name in points], 1)
        uv, z, heading = refine(torch, self.refiner, images, uv, tokens, offsets)
        where = self.model_camera.on_height(torch, torch.from_numpy(uv), torch.from_numpy(z)).numpy()
        k = points.index("object_position")
        at_rest = self.model_camera.on_height(torch, torch.from_numpy(uv[:, k:k + 1]),
                                              torch.full((len(images), 1), self.rest_height, dtype=torch.float64)).numpy()[:, 0]
        return out, (where, at_rest, heading)

    def fold(self, out, refined, resting):
        """One frame's answer from read's rows for it, the episode's frames so far folded in: its static
        fields averaged over the frames, a refined marker's position and heading their median; and the
        asset. resting: the moved object still rests on the table (the policy has not closed the gripper)."""
        out = out.copy()
        if refined is not None:
            where, at_rest, heading = refined
            points = self.refiner.points
            for kind, name in enumerate(points):
                out[FIELDS[name][0]:FIELDS[name][0] + 3] = where[kind]
            if resting:  # the moved object on the table: its height is the resting objects' of training
                out[FIELDS["object_position"][0]:FIELDS["object_position"][0] + 3] = at_rest
            if heading is not None:  # the upright marker turned by its heading
                self.markers.append(np.r_[where[points.index(HEADED)], np.cos(heading), np.sin(heading)])
        self.frames += 1
        self.static += (out[:ANSWER] - self.static) / self.frames
        self.asset_logits += out[HEAD:]
        y = out[:ANSWER].copy()
        for name in STATIC:
            c, n, _ = FIELDS[name]
            y[c:c + n] = self.static[c:c + n]
        if self.markers:  # the refined marker: the median over the frames (a frame whose first stage missed it is far off)
            m = np.median(self.markers, axis=0)
            heading = np.arctan2(m[4], m[3])
            y[FIELDS["second_position"][0]:FIELDS["second_position"][0] + 3] = m[:3]
            c = FIELDS["second_rotation"][0]
            y[c:c + 6] = [np.cos(heading), np.sin(heading), 0.0, -np.sin(heading), np.cos(heading), 0.0]
        return y, self.assets[int(np.argmax(self.asset_logits))]

    def __call__(self, image, instruction, resting=False):
        """fold of read of one image."""
        out, refined = self.read([image], instruction)
        return self.fold(out[0], frame_of(refined, 0), resting)


def frame_of(refined, i):
    """Frame i's entries of Perception.read's refined rows (None without a refinement)."""
    return refined and tuple(None if r is None else r[i] for r in refined)


def task_of(instruction, models):
    """The task whose training instructions make the instruction's words likeliest: naive Bayes,
    add-one smoothed over the words any task's training saw (the others tell no task apart)."""
    vocabulary = set().union(*(m.counts for m in models.values()))
    said = [w for w in words(instruction) if w in vocabulary]

    def log_likelihood(m):
        total = sum(m.counts.values()) + len(vocabulary)
        return sum(np.log((m.counts.get(w, 0) + 1) / total) for w in said)
    return max(sorted(models), key=lambda t: log_likelihood(models[t]))


def rotation_of_six(v):
    """The rotation whose first two columns are closest to v's (Gram-Schmidt)."""
    a = v[:3] / np.linalg.norm(v[:3])
    b = v[3:] - a * (a @ v[3:])
    b /= np.linalg.norm(b)
    return np.stack([a, b, np.cross(a, b)], 1)


def pose(position, six):
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = rotation_of_six(six), position
    return m


class Roles:
    """reference_policy.SceneRoles from what perception read: objects in role order (moved, then COLL's container)."""

    def __init__(self, task, y, asset):
        self.task, self.asset = task, asset
        self.roles = [0, 1] if task == "COLL" else [0]
        self.has_goal_pose = task != "COLL"
        self.goal = (y[19:22], rotation_of_six(y[22:28])) if self.has_goal_pose else (np.zeros(3), np.eye(3))
        self.obstacle = y[28:31] if task == "OVR" else np.zeros(3)


_perception = {}
_heads = {}
_episode = {"instruction": None, "task": None}


def load(torch):
    directory = os.environ.get("MANISOFT_PERCEPTION_MODELS")
    if not directory:
        raise RuntimeError("set MANISOFT_PERCEPTION_MODELS (image_policy.py train's directory) and, for a task without "
                           "<TASK>.head.pt there, MANISOFT_REFERENCE_MODELS (reference_policy.py train's directory)")
    paths = sorted(glob.glob(os.path.join(directory, "*.perception.pt")))
    if not paths:
        raise RuntimeError(f"MANISOFT_PERCEPTION_MODELS={directory}: no <TASK>.perception.pt")
    torch.set_num_threads(1)
    for p in paths:
        m = Perception(p, torch)
        _perception[m.task] = m


def reset():
    """Called by evaluate.py at the start of every episode: forgets the episode."""
    _episode["instruction"] = _episode["task"] = None
    _episode["closed"] = False
    for m in list(_perception.values()) + list(_heads.values()):
        m.reset()


def act(obs):
    """The harness's python:manisoft.image_policy:act (--action-mode ee_pose, the default image
    observation): the next end-effector target from obs["image"] and obs["instruction"]."""
    import torch
    if not _perception:
        load(torch)
    instruction = str(obs["instruction"])
    if _episode["instruction"] != instruction:
        _episode["instruction"] = instruction
        _episode["task"] = task_of(instruction, _perception)
    task = _episode["task"]
    if task not in _heads:
        path = os.path.join(os.environ["MANISOFT_PERCEPTION_MODELS"], f"{task}.head.pt")
        if not os.path.exists(path):
            if not os.environ.get("MANISOFT_REFERENCE_MODELS"):
                raise RuntimeError(f"no {path}: set MANISOFT_REFERENCE_MODELS (reference_policy.py train's directory)")
            path = os.path.join(os.environ["MANISOFT_REFERENCE_MODELS"], f"{task}.pt")
        _heads[task] = rp.Policy(path, torch)
    head = _heads[task]
    s = 0.0 if head.previous is None else float(head.previous[6] >= 0.5)
    _episode["closed"] = _episode.get("closed", False) or s > 0
    y, asset = _perception[task](obs["image"], instruction, resting=not _episode["closed"])
    return head(*seen_observation(_perception[task], y, asset, s, head.previous))


NEAR = 0.08  # m: the end effector is taken on its camera ray nearest the last command when that point is this close


def seen_observation(perception, y, asset, s, previous):
    """The privileged observation's entries (reference_policy.observed_features) and the scene's
    roles as perception read them (answer y, asset); S and previous the policy's last command (None
    before the first). The arm settles at its command and one view places the end effector least
    well along the camera ray (its height): where the point of the end effector's ray nearest the
    last command lies within NEAR of the perceived position, the end effector is taken there."""
    task, ee = perception.task, y[0:3]
    if previous is not None:
        origin = perception.model_camera.position
        ray = (ee - origin) / np.linalg.norm(ee - origin)
        nearest = origin + ray * ((previous[:3] - origin) @ ray)
        if np.linalg.norm(nearest - ee) < NEAR:
            ee = nearest
    objects = [pose(y[10:13], y[13:19])] + ([pose(y[19:22], y[22:28])] if task == "COLL" else [])
    seen = {"end_effector": pose(ee, y[3:9]), "gripper_width": max(y[9], 0.0), "gripper_state": s,
            "object_poses": np.stack(objects)}
    return seen, Roles(task, y, asset)


def curves(args):
    """The held-out errors per epoch (from model or checkpoint files' history): the first stage's
    located points (mean distances), and beside them, given refinement files, the refined points'
    median errors with the first stage's on the same frames (dotted)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker
    import torch
    saved = [torch.load(path) for path in args.models]
    refined = [m for m in saved if "points" in m]
    fig, axes = plt.subplots(1, 2 if refined else 1, figsize=(12.0 if refined else 6.4, 4.0), dpi=120, squeeze=False)
    styles = ("-", "--", ":", "-.")
    for m, style in zip([m for m in saved if "points" not in m], styles):
        epochs = [h[0] for h in m["history"]]
        for name, colour in zip(POINTS, ("C0", "C1", "C2", "C3")):
            values = [h[3].get(name) for h in m["history"]]
            if all(v is not None for v in values):
                axes[0, 0].plot(epochs, [100 * v for v in values], style, color=colour, marker="o", ms=3,
                                label=f"{m['task']}: {name.replace('_position', '').replace('second', 'container / marker')}")
    axes[0, 0].set_ylabel("held-out error, cm (mean distance)")
    axes[0, 0].set_title("First stage (96 x 96 crop): held-out position errors (valid mask)", fontsize=9)
    colours = {"ee_position": "C0", "object_position": "C1", "object_position at rest": "C4", "second_position": "C2"}
    for m, style in zip(refined, styles):
        epochs = [h[0] for h in m["history"]]
        for name, colour in colours.items():
            if name in m["history"][-1][3]:
                values = [h[3][name] for h in m["history"]]
                label = f"{m['task']}: {name.replace('_position', '').replace('second', 'marker')}"
                axes[0, 1].plot(epochs, [100 * v["refined"][0] for v in values], style, color=colour, marker="o", ms=3, label=label)
                axes[0, 1].plot(epochs, [100 * v["first stage"][0] for v in values], ":", color=colour, lw=1)
    if refined:
        axes[0, 1].set_ylabel("held-out error, cm (median distance)")
        axes[0, 1].set_title("Refined in 48 x 48 patches of the 384 x 384 image (dotted: the first stage on the same frames)",
                             fontsize=8)
    for ax in axes.flat:
        ax.xaxis.set_major_locator(matplotlib.ticker.MaxNLocator(integer=True))
        ax.set_xlabel("epoch")
        ax.set_ylim(bottom=0)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    rp.save_figure(fig, args.out)


def main(argv=None):
    p = argparse.ArgumentParser(description="The image + instruction reference policy on the end-effector track: train its perception, plot")
    sub = p.add_subparsers(dest="command", required=True)
    t = sub.add_parser("train", help="train one perception model per task on rendered frames of a generated dataset")
    t.add_argument("--data", required=True, action="append",
                   help="DATASET_DIR:IMAGES_DIR (generate_dataset's folder and render_dataset's for it; repeat for more)")
    t.add_argument("--out", required=True, help="directory for <TASK>.perception.pt")
    t.add_argument("--tasks", default="ALN,COLL")
    r = sub.add_parser("refine", help="train one refinement model per task: the end effector and the moved object located "
                       "again in full-resolution patches (frames rendered at 384 x 384)")
    r.add_argument("--data", required=True, action="append", help="DATASET_DIR:IMAGES_DIR, as train's, rendered at 384 x 384")
    r.add_argument("--perception", required=True, help="train's directory: the first stage (<TASK>.perception.pt)")
    r.add_argument("--out", required=True, help="directory for <TASK>.refine.pt (put it beside <TASK>.perception.pt to use it)")
    r.add_argument("--tasks", default="COLL")
    r.add_argument("--valid-every", type=int, default=2, help="every K-th valid frame gives the held-out errors")
    for stage, epochs in ((t, 6), (r, 4)):
        stage.add_argument("--epochs", type=int, default=epochs)
        stage.add_argument("--batch", type=int, default=64)
        stage.add_argument("--lr", type=float, default=1e-3)
        stage.add_argument("--lr-decay", type=float, default=0.1, help="the learning rate falls by this factor over the run")
        stage.add_argument("--rest-weight", type=float, default=4.0, help="how much more often frames of the moved object at rest are drawn")
        stage.add_argument("--word-drop", type=float, default=0.15, help="the chance a training instruction's word is replaced by 'unknown'")
        rp.add_run_flags(stage)
    h = sub.add_parser("adapt", help="train the privileged policy's model further on the state perception reads off the "
                       "rendered frames (a frame every 36 control steps, the model's rate), as <TASK>.head.pt used beside the perception")
    h.add_argument("--data", required=True, action="append", help="DATASET_DIR:IMAGES_DIR, as refine's")
    h.add_argument("--perception", required=True, help="the perception's directory (<TASK>.perception.pt, <TASK>.refine.pt)")
    h.add_argument("--reference", required=True, help="reference_policy.py train's directory (<TASK>.pt, where it starts)")
    h.add_argument("--out", required=True, help="directory for <TASK>.head.pt (put it beside <TASK>.perception.pt to use it)")
    h.add_argument("--tasks", default="ALN")
    h.add_argument("--setting", choices=("clean", "randomized", "all"), default="clean",
                   help="the scenes whose frames it trains on (randomized scenes' perceived state is far off; trained on "
                   "them too the head does worse on both)")
    rp.add_fit_flags(h, epochs=10, lr=3e-4)
    c = sub.add_parser("curves", help="plot the held-out position errors per epoch of trained models")
    c.add_argument("models", nargs="+", help="<TASK>.perception.pt and <TASK>.refine.pt files (or their .checkpoint)")
    c.add_argument("--out", required=True, help="PNG file")
    args = p.parse_args(argv)
    {"train": train, "refine": train_refiners, "adapt": adapt_heads, "curves": curves}[args.command](args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
