#!/usr/bin/env python3
"""A small learned baseline: behaviour cloning from the camera image and the
instruction to an action chunk, trained on CPU with PyTorch (Debian python3-torch) on expert
episodes, evaluated by the harness like any policy. It shows the loop end to end; it is not meant to
compete with the paper's 400M-parameter policies.

    export PYTHONPATH=build/gcc-release/python:examples/python
    python3 examples/python/bc_baseline.py collect --episodes-per-task 40 --out bc/data.npz
    python3 examples/python/bc_baseline.py train --data bc/data.npz --out bc/model.pt
    MANISOFT_BC_MODEL=bc/model.pt python3 examples/python/evaluate.py --policy python:bc_baseline:act \\
        --image-size 64 64 --chunk-steps 8 --episodes-per-category 2 --task all --setting all --out bc/eval

Data: expert episodes of the train split (half clean, half randomized scenes, every outcome kept:
the expert's actions are the expert's even when the episode times out), the image rendered at
64 x 64 from the benchmark camera every --every control steps, with the instruction and the next
H expert actions as the target chunk. Model: three strided convolutions and a mean of learned word
embeddings, an MLP to H x 61 outputs: torques as tanh times the actuation limit, S as a logit.
Loss: mean squared error of the normalised torques plus the binary cross-entropy of S.
"""
import argparse
import os
import re
import sys
import time

import numpy as np

import manisoft

TASKS = tuple(t["name"] for t in manisoft.tasks())


def words(text):
    return re.findall(r"[a-z']+", text.lower())


def collect(args):
    camera = {"width": args.image_size, "height": args.image_size}
    images, texts, chunks, episodes = [], [], [], []
    t0 = time.perf_counter()
    for task in TASKS:
        envs = {s: manisoft.make_env(task, s, seed=args.seed, render=True, camera=camera) for s in ("clean", "randomized")}
        for k in range(args.episodes_per_task):
            setting = "clean" if k % 2 == 0 else "randomized"
            env = envs[setting]
            obs, info = env.reset(options={"index": k // 2, "instruction": "seen", "instruction_index": k})
            frames, actions = [], []
            while True:
                if len(actions) % args.every == 0:
                    frames.append((len(actions), obs["image"], obs["instruction"]))
                a = env.expert_action()
                actions.append(a)
                obs, _, terminated, truncated, info = env.step(a)
                if terminated or truncated:
                    break
            actions = np.asarray(actions)
            for t, image, text in frames:
                chunk = actions[t:t + args.horizon]
                if len(chunk) < args.horizon:  # pad with the last action
                    chunk = np.concatenate([chunk, np.repeat(chunk[-1:], args.horizon - len(chunk), axis=0)])
                images.append(image)
                texts.append(text)
                chunks.append(chunk.astype(np.float32))
            episodes.append((task, setting, k // 2, info["success"], info["steps"]))
            print(f"{task} {setting} {k // 2}: {'success' if info['success'] else info['failure']} after {info['steps']} steps, "
                  f"{len(images)} samples, {time.perf_counter() - t0:.0f} s", flush=True)
    space = envs["clean"].action_space
    tmp = args.out + ".tmp.npz"
    np.savez_compressed(tmp, images=np.asarray(images), texts=np.asarray(texts), chunks=np.asarray(chunks), high=space.high,
                        episodes=np.asarray([f"{t} {s} {i} {int(ok)} {n}" for t, s, i, ok, n in episodes]))
    os.replace(tmp, args.out)
    ok = sum(e[3] for e in episodes)
    print(f"{len(episodes)} episodes ({ok} successful), {len(images)} samples -> {args.out}")


def build_model(torch, vocab_size, horizon, action_size):
    nn = torch.nn

    class Policy(nn.Module):
        def __init__(self):
            super().__init__()
            self.vision = nn.Sequential(
                nn.Conv2d(3, 32, 5, stride=2, padding=2), nn.ReLU(),
                nn.Conv2d(32, 64, 3, stride=2, padding=1), nn.ReLU(),
                nn.Conv2d(64, 64, 3, stride=2, padding=1), nn.ReLU(),
                nn.AdaptiveAvgPool2d(4), nn.Flatten())
            self.text = nn.EmbeddingBag(vocab_size, 64, mode="mean")
            self.head = nn.Sequential(nn.Linear(64 * 16 + 64, 512), nn.ReLU(), nn.Linear(512, horizon * action_size))
            self.horizon, self.action_size = horizon, action_size

        def forward(self, images, tokens, offsets):
            x = self.vision(images.permute(0, 3, 1, 2).float() / 255.0)
            return self.head(torch.cat([x, self.text(tokens, offsets)], 1)).view(-1, self.horizon, self.action_size)

    return Policy()


def encode(torch, texts, vocab):
    tokens, offsets = [], []
    for t in texts:
        offsets.append(len(tokens))
        tokens += [vocab.get(w, 0) for w in words(t)] or [0]
    return torch.tensor(tokens, dtype=torch.long), torch.tensor(offsets, dtype=torch.long)


def loss_of(torch, output, target, high):
    torques = torch.tanh(output[..., :-1])
    scale = torch.where(high[:-1] > 0, high[:-1], torch.ones_like(high[:-1]))
    torque_loss = ((torques - target[..., :-1] / scale) ** 2).mean()
    gripper_loss = torch.nn.functional.binary_cross_entropy_with_logits(output[..., -1], (target[..., -1] >= 0.5).float())
    return torque_loss + gripper_loss


def train(args):
    import torch
    torch.manual_seed(args.seed)
    torch.set_num_threads(args.threads)
    data = np.load(args.data)
    images, texts, chunks, high = data["images"], data["texts"], data["chunks"], torch.tensor(data["high"], dtype=torch.float32)
    vocab = {"<unk>": 0}
    for t in texts:
        for w in words(str(t)):
            vocab.setdefault(w, len(vocab))
    horizon, action_size = chunks.shape[1], chunks.shape[2]
    model = build_model(torch, len(vocab), horizon, action_size)
    optimiser = torch.optim.Adam(model.parameters(), lr=args.lr)
    rng = np.random.default_rng(args.seed)
    order = rng.permutation(len(images))
    valid = order[: len(order) // 10]
    training = order[len(order) // 10:]
    images_t, chunks_t = torch.from_numpy(images), torch.from_numpy(chunks)
    training, valid = torch.from_numpy(training), torch.from_numpy(valid)
    t0 = time.perf_counter()
    for epoch in range(args.epochs):
        model.train()
        total = 0.0
        for start in range(0, len(training), args.batch):
            idx = training[start:start + args.batch]
            tokens, offsets = encode(torch, [str(texts[i]) for i in idx.tolist()], vocab)
            loss = loss_of(torch, model(images_t[idx], tokens, offsets), chunks_t[idx], high)
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
            total += loss.item() * len(idx)
        training = training[torch.from_numpy(rng.permutation(len(training)))]
        model.eval()
        with torch.no_grad():
            tokens, offsets = encode(torch, [str(texts[i]) for i in valid.tolist()], vocab)
            valid_loss = loss_of(torch, model(images_t[valid], tokens, offsets), chunks_t[valid], high).item()
        print(f"epoch {epoch + 1}/{args.epochs}: train loss {total / len(training):.4f}, held-out loss {valid_loss:.4f}, "
              f"{time.perf_counter() - t0:.0f} s", flush=True)
    tmp = args.out + ".tmp"
    torch.save({"state": model.state_dict(), "vocab": vocab, "high": data["high"], "horizon": horizon, "action_size": action_size,
                "image_size": images.shape[1]}, tmp)
    os.replace(tmp, args.out)
    print(f"model -> {args.out}")


_policy = None


def act(obs):
    """The harness's python:bc_baseline:act: a chunk (H, 61) for the observation. The model file is
    $MANISOFT_BC_MODEL; the image must have the size it was trained at (--image-size)."""
    global _policy
    import torch
    if _policy is None:
        path = os.environ.get("MANISOFT_BC_MODEL")
        if not path:
            raise RuntimeError("set MANISOFT_BC_MODEL to a model written by bc_baseline.py train")
        saved = torch.load(path)
        model = build_model(torch, len(saved["vocab"]), saved["horizon"], saved["action_size"])
        model.load_state_dict(saved["state"])
        model.eval()
        torch.set_num_threads(1)
        _policy = (model, saved)
    model, saved = _policy
    image = obs["image"]
    if image.shape[0] != saved["image_size"]:
        raise ValueError(f"image is {image.shape[0]} pixels high, the model was trained at {saved['image_size']} (--image-size)")
    with torch.no_grad():
        tokens, offsets = encode(torch, [obs["instruction"]], saved["vocab"])
        out = model(torch.from_numpy(np.ascontiguousarray(image))[None], tokens, offsets)[0]
    chunk = np.empty((out.shape[0], out.shape[1]))
    chunk[:, :-1] = np.tanh(out[:, :-1].numpy()) * saved["high"][:-1]
    chunk[:, -1] = (out[:, -1].numpy() > 0).astype(np.float64)
    return chunk


def main(argv=None):
    p = argparse.ArgumentParser(description="Behaviour-cloning baseline: collect expert data, train")
    sub = p.add_subparsers(dest="command", required=True)
    c = sub.add_parser("collect")
    c.add_argument("--episodes-per-task", type=int, default=40)
    c.add_argument("--seed", type=int, default=0)
    c.add_argument("--image-size", type=int, default=64)
    c.add_argument("--every", type=int, default=4, help="a sample every this many control steps")
    c.add_argument("--horizon", type=int, default=8, help="actions in a chunk")
    c.add_argument("--out", required=True)
    t = sub.add_parser("train")
    t.add_argument("--data", required=True)
    t.add_argument("--out", required=True)
    t.add_argument("--epochs", type=int, default=8)
    t.add_argument("--batch", type=int, default=128)
    t.add_argument("--lr", type=float, default=1e-3)
    t.add_argument("--seed", type=int, default=0)
    t.add_argument("--threads", type=int, default=2)
    args = p.parse_args(argv)
    (collect if args.command == "collect" else train)(args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
