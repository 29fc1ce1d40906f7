#!/usr/bin/env python3
"""The paper's learned executor (section 3.4, appendix "Details for Executor Training"): an MLP
policy trained with soft actor-critic (SAC) on the batched reach environment, or cloned from the
model executor (distill), exported in the weight format of control/mlp_executor.hpp so that
`reach_eval --executor mlp --weights FILE` evaluates it beside the model executor. What each
reaches, and why SAC falls short of the paper's executor here: BENCHMARKS.md, "Learned executors".

    /usr/bin/python3 -m manisoft.sac_executor train --out sac/run --minutes 60
    /usr/bin/python3 -m manisoft.sac_executor distill --out sac/distilled
    /usr/bin/python3 -m manisoft.sac_executor export sac/run/checkpoint.pt sac/executor.mlp
    reach_eval --executor mlp --weights sac/executor.mlp --targets 100 --seed 1 --set table
    /usr/bin/python3 -m manisoft.sac_executor curves sac/curves.png sac/run

Environment: manisoft.make_vec_env("reach", --envs) (every arm its own target of the table set;
the paper's arm, 714 Hz control, horizon 1500 control steps). The reward is the environment's own
(reward/distance_reward.hpp R_d plus reward/stability_reward.hpp R_s with beta = --stability-beta:
the paper trains with R_d alone, then post-trains with R_s: --init a trained run's checkpoint, and
--anchor W to hold the actor near it).
Observation (the paper's: target pose, current end-effector pose, positions and velocities of
every second node of the arm): exactly the MLP executor's features (mlp_executor.hpp), normalised
by a fixed affine map measured on the first round's states (it is folded into the exported
network's first layer). Action: a tanh-squashed Gaussian of 12 values in (-1, 1), per torque axis
a torque profile along the arm (constant, linear and quadratic terms over elements 1..18, and the
tip element's own value; basis()), in units of the axis's limit: the model executor's holding
torques have this shape (linear along the arm, the tip element apart), and 57 independent element
torques did not learn. The exported network ends with the basis as a linear layer, so it outputs
the element torques. The policy decides every --repeat control steps (default 1: the arm's held
poses need a loop at the control rate) and its torques are held in between (the exported executor
decides at every control step). The decision's reward is the mean of its control steps' rewards.
SAC: twin critics with target networks (Polyak tau = 0.005), an entropy temperature tuned to the
target entropy -12, Adam at the paper's learning rate 3e-4 and batch 256, gamma per decision.
Rounds: every arm starts an episode of its own seed (distinct from reach_eval's target seeds) at
the start of a round and runs the full horizon; an arm whose simulation diverges ends its episode
as terminal and starts the next of its seeds. The time limit at a round's end is not terminal.
After every round: a progress line; every --eval-every rounds: the deterministic policy, acting at
every control step like the exported executor, on --eval-targets fixed targets (reach_eval's seed
--eval-seed: held out from training and from the test seed), its success (tolerance 0.03 m / 0.3 rad
held 100 control steps) and reach (within tolerance at any step: the paper's criterion).
Checkpoints at round boundaries every --checkpoint-minutes and at the end (temporary file, then
renamed): networks, optimisers, replay buffer, random generators and log; --resume continues from
one and ends with the weights an uninterrupted run gives (CPU, the same --torch-threads).
"""
import argparse
import math
import os
import sys
import time

import numpy as np

TRAIN_SEED_BASE = 1 << 40  # training episodes' seeds start here; reach_eval's are seed * 1000003 + i
EVAL_SEED_STRIDE = 1000003  # reach_eval's target seeds: seed * 1000003 + i
ROWS = 20  # action rows (elements); element 0 takes no torque
PROFILE = 4  # values per torque axis: the profile's constant, linear and quadratic terms over elements 1..18, the tip element


def features(obs):
    """The MLP executor's features (mlp_executor.hpp) of a batch of reach observations: B x (24 + 6 m)."""
    t, e = obs["target"], obs["end_effector"]
    b = t.shape[0]
    return np.concatenate([
        t[:, :3, 3], t[:, :3, :3].transpose(0, 2, 1).reshape(b, 9),  # rotation column-major
        e[:, :3, 3], e[:, :3, :3].transpose(0, 2, 1).reshape(b, 9),
        obs["node_positions"].reshape(b, -1), obs["node_velocities"].reshape(b, -1)], axis=1)


def basis(high):
    """The 60 x 12 map from the policy's squashed values to the element torques (row-major, element 0
    zero). Per axis c: elements 1..18 get high_c (a + b x + q (3 x^2 - 1) / 2) with x from -1 to 1
    along them, the tip element high_c t; the arm world clamps the sum to the limits."""
    x = np.linspace(-1, 1, ROWS - 2)
    out = np.zeros((ROWS * 3, 3 * PROFILE))
    for c in range(3):
        for r in range(1, ROWS - 1):
            xr = x[r - 1]
            out[r * 3 + c, c * PROFILE:c * PROFILE + 3] = high[r, c] * np.array([1.0, xr, (3 * xr * xr - 1) / 2])
        out[(ROWS - 1) * 3 + c, c * PROFILE + 3] = high[ROWS - 1, c]
    return out


def torques(u, b):
    """Squashed values (B x 12) -> B x 20 x 3 element torques through basis b."""
    return (u @ b.T).reshape(u.shape[0], ROWS, 3)


def build(torch, nn, obs_size, act_size, hidden):
    """Actor (mean and log-std heads) and twin critics."""

    def mlp(n_in, n_out):
        layers, size = [], n_in
        for h in hidden:
            layers += [nn.Linear(size, h), nn.ReLU()]
            size = h
        layers.append(nn.Linear(size, n_out))
        return nn.Sequential(*layers)

    actor = mlp(obs_size, 2 * act_size)
    critics = nn.ModuleList([mlp(obs_size + act_size, 1), mlp(obs_size + act_size, 1)])
    return actor, critics


class Sac:
    """Soft actor-critic (Haarnoja et al. 2018, with the learned temperature of the 2019 version)."""

    def __init__(self, torch, nn, obs_size, act_size, args):
        self.torch, self.args, self.act_size = torch, args, act_size
        self.actor, self.critics = build(torch, nn, obs_size, act_size, args.hidden)
        _, self.targets = build(torch, nn, obs_size, act_size, args.hidden)
        self.targets.load_state_dict(self.critics.state_dict())
        self.log_alpha = torch.zeros(1, requires_grad=True)
        self.actor_opt = torch.optim.Adam(self.actor.parameters(), lr=getattr(args, "actor_lr", None) or args.lr)
        self.critic_opt = torch.optim.Adam(self.critics.parameters(), lr=args.lr)
        self.alpha_opt = torch.optim.Adam([self.log_alpha], lr=args.lr)
        self.norm_mean = torch.zeros(obs_size)
        self.norm_scale = torch.ones(obs_size)
        self.generator = torch.Generator().manual_seed(args.seed)
        self.anchor = None  # set_anchor(): a frozen copy of the actor that the actor is held near

    def set_anchor(self):
        """Freezes a copy of the current actor: from now on the actor's loss is normalised by the
        critics' scale and adds --anchor x the squared distance of its deterministic action from the
        copy's (as TD3+BC holds a policy near its data), so that post-training stays near the start."""
        import copy
        self.anchor = copy.deepcopy(self.actor)
        for p in self.anchor.parameters():
            p.requires_grad_(False)

    def policy(self, obs):
        """Squashed sample, its log-probability, and the deterministic action tanh(mean)."""
        torch = self.torch
        out = self.actor((obs - self.norm_mean) / self.norm_scale)
        mean, log_std = out[:, :self.act_size], out[:, self.act_size:].clamp(-5, 2)
        noise = torch.randn(mean.shape, generator=self.generator)
        pre = mean + log_std.exp() * noise
        u = torch.tanh(pre)
        # log N(pre; mean, std) - sum log(1 - tanh(pre)^2), the latter in a stable form
        log_prob = (-0.5 * noise.pow(2) - log_std - 0.5 * math.log(2 * math.pi)).sum(1)
        log_prob = log_prob - (2 * (math.log(2) - pre - torch.nn.functional.softplus(-2 * pre))).sum(1)
        return u, log_prob, torch.tanh(mean)

    def q(self, nets, obs, u):
        x = self.torch.cat([(obs - self.norm_mean) / self.norm_scale, u], dim=1)
        return nets[0](x).squeeze(1), nets[1](x).squeeze(1)

    def update(self, batch, train_actor=True):
        """One gradient step of the critics and, when train_actor, of the actor and the temperature."""
        torch, a = self.torch, self.args
        obs, u, reward, next_obs, done = (torch.from_numpy(x) for x in batch)
        alpha = self.log_alpha.exp().detach()
        with torch.no_grad():
            next_u, next_logp, _ = self.policy(next_obs)
            q1, q2 = self.q(self.targets, next_obs, next_u)
            target = reward + a.gamma * (1 - done) * (torch.min(q1, q2) - alpha * next_logp)
        q1, q2 = self.q(self.critics, obs, u)
        critic_loss = (q1 - target).pow(2).mean() + (q2 - target).pow(2).mean()
        self.critic_opt.zero_grad()
        critic_loss.backward()
        self.critic_opt.step()
        if not train_actor:
            self.polyak()
            return float(critic_loss), 0.0, float(alpha)
        for p in self.critics.parameters():
            p.requires_grad_(False)
        new_u, logp, mean_u = self.policy(obs)
        q = torch.min(*self.q(self.critics, obs, new_u))
        actor_loss = (alpha * logp - q).mean()
        if self.anchor is not None:
            with torch.no_grad():
                start = torch.tanh(self.anchor((obs - self.norm_mean) / self.norm_scale)[:, :self.act_size])
            actor_loss = actor_loss / q.abs().mean().detach().clamp(min=1e-6) + a.anchor * (mean_u - start).pow(2).sum(1).mean()
        self.actor_opt.zero_grad()
        actor_loss.backward()
        self.actor_opt.step()
        for p in self.critics.parameters():
            p.requires_grad_(True)
        alpha_loss = -(self.log_alpha * (logp.detach() - self.act_size)).mean()  # target entropy -act_size
        self.alpha_opt.zero_grad()
        alpha_loss.backward()
        self.alpha_opt.step()
        self.polyak()
        return float(critic_loss), float(actor_loss), float(alpha)

    def polyak(self):
        with self.torch.no_grad():
            for p, t in zip(self.critics.parameters(), self.targets.parameters()):
                t.mul_(1 - self.args.tau).add_(self.args.tau * p)

    def state(self):
        return {"actor": self.actor.state_dict(), "critics": self.critics.state_dict(), "targets": self.targets.state_dict(),
                "log_alpha": self.log_alpha.detach().clone(), "actor_opt": self.actor_opt.state_dict(),
                "critic_opt": self.critic_opt.state_dict(), "alpha_opt": self.alpha_opt.state_dict(),
                "norm_mean": self.norm_mean, "norm_scale": self.norm_scale, "generator": self.generator.get_state(),
                "anchor": None if self.anchor is None else self.anchor.state_dict()}

    def load(self, s, weights_only=False):
        self.actor.load_state_dict(s["actor"])
        self.critics.load_state_dict(s["critics"])
        self.targets.load_state_dict(s["targets"])
        self.norm_mean, self.norm_scale = s["norm_mean"], s["norm_scale"]
        if weights_only:
            return
        with self.torch.no_grad():
            self.log_alpha.copy_(s["log_alpha"])
        self.actor_opt.load_state_dict(s["actor_opt"])
        self.critic_opt.load_state_dict(s["critic_opt"])
        self.alpha_opt.load_state_dict(s["alpha_opt"])
        self.generator.set_state(s["generator"])
        if s.get("anchor") is not None:
            self.set_anchor()
            self.anchor.load_state_dict(s["anchor"])


class Replay:
    """A ring buffer of decisions (float32), sampled uniformly with its own generator."""

    def __init__(self, capacity, obs_size, act_size, seed):
        self.obs = np.zeros((capacity, obs_size), np.float32)
        self.next_obs = np.zeros((capacity, obs_size), np.float32)
        self.u = np.zeros((capacity, act_size), np.float32)
        self.reward = np.zeros(capacity, np.float32)
        self.done = np.zeros(capacity, np.float32)
        self.size = self.next = 0
        self.rng = np.random.default_rng(seed)

    def add(self, obs, u, reward, next_obs, done):
        n = len(obs)
        at = (self.next + np.arange(n)) % len(self.obs)
        self.obs[at], self.u[at], self.reward[at], self.next_obs[at], self.done[at] = obs, u, reward, next_obs, done
        self.next = int((self.next + n) % len(self.obs))
        self.size = min(self.size + n, len(self.obs))

    def sample(self, n):
        i = self.rng.integers(0, self.size, n)
        return self.obs[i], self.u[i], self.reward[i], self.next_obs[i], self.done[i]

    def state(self):
        return {"obs": self.obs[:self.size].copy(), "next_obs": self.next_obs[:self.size].copy(), "u": self.u[:self.size].copy(),
                "reward": self.reward[:self.size].copy(), "done": self.done[:self.size].copy(), "next": self.next,
                "rng": self.rng.bit_generator.state}

    def load(self, s):
        self.size, self.next = len(s["obs"]), s["next"]
        for key in ("obs", "next_obs", "u", "reward", "done"):
            getattr(self, key)[:self.size] = s[key]
        self.rng.bit_generator.state = s["rng"]


def evaluate(sac, env, b, seed, count, horizon):
    """Deterministic policy at every control step on reach_eval's targets seed * 1000003 + i:
    (success fraction, reached fraction, mean final position error, mean final rotation error)."""
    torch = sac.torch
    obs, _ = env.reset(seed=[seed * EVAL_SEED_STRIDE + i for i in range(count)])
    reached = np.zeros(count, bool)
    success = np.zeros(count, bool)
    for _ in range(horizon):
        with torch.no_grad():
            _, _, u = sac.policy(torch.from_numpy(features(obs).astype(np.float32)))
        obs, _, terminated, truncated, info = env.step(torques(u.numpy().astype(np.float64), b))
        reached |= (info["position_error"] < 0.03) & (info["rotation_error"] < 0.3)
        success |= info["success"]
        if (terminated | truncated).all():
            break
    return (float(success.mean()), float(reached.mean()), float(np.mean(info["position_error"])),
            float(np.mean(info["rotation_error"])))


def save_atomic(torch, obj, path):
    tmp = path + ".tmp"
    torch.save(obj, tmp)
    os.replace(tmp, path)


def train(args):
    import torch
    import torch.nn as nn
    import manisoft

    torch.set_num_threads(args.torch_threads)
    torch.manual_seed(args.seed)
    os.makedirs(args.out, exist_ok=True)
    checkpoint = os.path.join(args.out, "checkpoint.pt")
    env = manisoft.make_vec_env("reach", args.envs, num_threads=args.threads, horizon=args.horizon, stability_beta=args.stability_beta)
    b = basis(np.asarray(env.single_action_space.high))
    horizon = env.horizon
    if horizon % args.repeat:
        sys.exit(f"--repeat {args.repeat} must divide the horizon {horizon}")
    decisions = horizon // args.repeat
    if args.anchor > 0 and not args.init:
        sys.exit("--anchor holds the actor near an --init policy: give --init")
    obs, _ = env.reset(seed=TRAIN_SEED_BASE)
    obs_size, act_size = features(obs).shape[1], b.shape[1]
    sac = Sac(torch, nn, obs_size, act_size, args)
    replay = Replay(args.buffer, obs_size, act_size, args.seed)
    explore = np.random.default_rng(args.seed + 1)
    log, round_, updates, start_seconds = [], 0, 0, 0.0
    if args.resume and os.path.exists(checkpoint):
        s = torch.load(checkpoint)
        sac.load(s["sac"])
        replay.load(s["replay"])
        explore.bit_generator.state = s["explore"]
        log, round_, updates, start_seconds = s["log"], s["round"], s["updates"], s["seconds"]
        print(f"resumed at round {round_} ({updates} updates)", flush=True)
    elif args.init:
        sac.load(torch.load(args.init)["sac"], weights_only=True)
        if args.init_log_std is not None:  # a fixed exploration noise around the loaded policy's mean
            head = sac.actor[-1]
            with torch.no_grad():
                head.weight[act_size:].zero_()
                head.bias[act_size:].fill_(args.init_log_std)
        with torch.no_grad():
            sac.log_alpha.fill_(math.log(args.init_alpha))
        if args.anchor > 0:
            sac.set_anchor()
        print(f"initialised from {args.init}", flush=True)
    eval_env = manisoft.make_vec_env("reach", args.eval_targets, num_threads=args.threads, horizon=args.horizon,
                                     stability_beta=args.stability_beta)
    started, last_checkpoint = time.time(), time.time()

    def seconds():
        return start_seconds + time.time() - started

    def write_checkpoint():
        save_atomic(torch, {"sac": sac.state(), "replay": replay.state(), "explore": explore.bit_generator.state, "log": log,
                            "round": round_, "updates": updates, "seconds": seconds(), "args": vars(args)}, checkpoint)

    while (args.rounds is None or round_ < args.rounds) and (args.minutes is None or seconds() < 60 * args.minutes):
        obs, _ = env.reset(seed=TRAIN_SEED_BASE + (args.seed << 32) + round_ * args.envs)
        f = features(obs).astype(np.float32)
        if round_ == 0 and not args.init:  # the fixed input normalisation, from the first round's states under random actions
            sample = []
        stats = {"reward": 0.0, "diverged": 0, "critic": 0.0, "actor": 0.0}
        credit = 0.0
        for _ in range(decisions):
            if (replay.size < args.warmup or round_ == 0) and not args.init:
                u = explore.uniform(-1, 1, (args.envs, act_size)).astype(np.float32)
            else:
                with torch.no_grad():
                    u = sac.policy(torch.from_numpy(f))[0].numpy()
            action = torques(u.astype(np.float64), b)
            reward, alive, terminal = np.zeros(args.envs), np.ones(args.envs, bool), np.zeros(args.envs, bool)
            for _ in range(args.repeat):
                obs, r, terminated, _, info = env.step(action)
                reward += np.where(alive, r, 0.0)
                terminal |= terminated & alive
                alive &= ~terminated
            if terminal.any():  # start the arms' next episodes now (the autoreset would ignore an action)
                obs, _ = env.reset(options={"reset_mask": terminal.copy()})
            next_f = features(obs).astype(np.float32)
            replay.add(f, u, (reward / args.repeat).astype(np.float32), next_f, terminal.astype(np.float32))
            if round_ == 0 and not args.init:
                sample.append(f)
            stats["reward"] += float(reward.mean()) / horizon
            stats["diverged"] += int(terminal.sum())
            f = next_f
            credit += args.updates
            if replay.size >= args.warmup and (round_ > 0 or args.init):  # the input normalisation is set after round 0
                while credit >= 1:
                    c, a, alpha = sac.update(replay.sample(args.batch), updates >= args.actor_delay)
                    credit -= 1
                    updates += 1
                    stats["critic"] += c
                    stats["actor"] += a
            else:
                credit = 0.0
        if round_ == 0 and not args.init:
            x = np.concatenate(sample)
            sac.norm_mean = torch.from_numpy(x.mean(0))
            sac.norm_scale = torch.from_numpy(np.maximum(x.std(0), 1e-2))
        round_ += 1
        entry = {"round": round_, "control_steps": round_ * args.envs * horizon, "updates": updates, "seconds": round(seconds(), 1),
                 "train_reward": stats["reward"], "train_success": float(np.mean(info["success"])),
                 "train_position_error": float(np.mean(info["position_error"])), "diverged": stats["diverged"],
                 "alpha": float(sac.log_alpha.exp()), "critic_loss": stats["critic"] / max(1.0, decisions * args.updates)}
        if round_ % args.eval_every == 0:
            ev = evaluate(sac, eval_env, b, args.eval_seed, args.eval_targets, horizon)
            entry.update(eval_success=ev[0], eval_reached=ev[1], eval_position_error=ev[2], eval_rotation_error=ev[3])
        log.append(entry)
        print(f"round {round_}: {entry['control_steps'] / 1e6:.2f} M control steps, {updates} updates, {entry['seconds']:.0f} s, "
              f"reward {entry['train_reward']:.3f}, train success {entry['train_success']:.2f} (final |d_p| "
              f"{entry['train_position_error']:.3f} m), alpha {entry['alpha']:.3g}"
              + (f", eval success {entry['eval_success']:.2f} reached {entry['eval_reached']:.2f} (|d_p| {entry['eval_position_error']:.3f} m)"
                 if "eval_success" in entry else ""), flush=True)
        if time.time() - last_checkpoint > 60 * args.checkpoint_minutes or (args.stop_after and round_ == args.stop_after):
            write_checkpoint()
            last_checkpoint = time.time()
        if args.stop_after and round_ == args.stop_after:
            return
    write_checkpoint()


def distill(args):
    """Behaviour cloning of the model executor (control/model_executor.hpp) into the same actor,
    with DAgger: iteration 0 drives the arm with the model executor's torques plus Gaussian noise
    of --noise N m on every actuated entry (so that the samples show recoveries), iteration i > 0
    with the blend beta a_executor + (1 - beta) a_network, beta = 2^-i; every iteration records the
    model executor's action at the states visited, and the network is refitted on everything
    recorded (squared torque error in units of the limits, through basis()). After every iteration
    the network is evaluated on the held-out targets at the environment's horizon and written to
    checkpoint.pt; best.pt keeps the iteration that reached the most of them (then held the most).
    The checkpoints have the trainer's layout, so `export` writes them and `train --init` starts SAC
    from one."""
    import torch
    import torch.nn as nn
    import manisoft

    torch.set_num_threads(args.torch_threads)
    torch.manual_seed(args.seed)
    os.makedirs(args.out, exist_ok=True)
    env = manisoft.make_env("reach", horizon=args.horizon)
    high = np.asarray(env.action_space.high)
    b = basis(high)
    b_t = torch.from_numpy((b / high.reshape(-1)[:, None].clip(min=1)).T.copy()).float()  # torques in units of the limits
    obs, _ = env.reset(seed=0)
    one = lambda o: {k: np.asarray(v)[None] for k, v in o.items() if k != "time"}  # noqa: E731
    args.gamma, args.tau = 0.99, 0.005  # unused by cloning; kept so the checkpoint trains on
    sac = Sac(torch, nn, features(one(obs)).shape[1], b.shape[1], args)
    optimiser = torch.optim.Adam(sac.actor.parameters(), lr=args.lr)
    batches = np.random.default_rng(args.seed)
    inputs, labels, log, started = [], [], [], time.time()
    eval_env = manisoft.make_vec_env("reach", args.eval_targets, num_threads=args.threads)  # reach_eval's horizon
    best = None
    for it in range(args.iterations):
        for k in range(args.targets):
            obs, _ = env.reset(seed=TRAIN_SEED_BASE + (args.seed << 32) + it * args.targets + k)
            for t in range(args.horizon):
                expert = np.array(env.expert_action())
                f = features(one(obs))
                if t % args.stride == 0:
                    inputs.append(f[0].astype(np.float32))
                    labels.append((expert / high.clip(min=1)).reshape(-1).astype(np.float32))
                if it > 0:
                    with torch.no_grad():
                        _, _, u = sac.policy(torch.from_numpy(f.astype(np.float32)))
                    beta = 0.5 ** it
                    action = beta * expert + (1 - beta) * torques(u.numpy().astype(np.float64), b)[0]
                else:
                    action = expert + batches.normal(scale=args.noise, size=expert.shape) * (high > 0)
                obs, _, terminated, truncated, _ = env.step(action)
                if terminated or truncated:
                    break
        x, y = torch.from_numpy(np.stack(inputs)), torch.from_numpy(np.stack(labels))
        if it == 0:
            sac.norm_mean = x.mean(0)
            sac.norm_scale = x.std(0).clamp(min=1e-2)
        for _ in range(args.epochs):
            order = torch.from_numpy(batches.permutation(len(x)))
            for i in range(0, len(x), args.batch):
                idx = order[i:i + args.batch]
                out = sac.actor((x[idx] - sac.norm_mean) / sac.norm_scale)
                loss = (torch.tanh(out[:, :b.shape[1]]) @ b_t - y[idx]).pow(2).mean()
                optimiser.zero_grad()
                loss.backward()
                optimiser.step()
        ev = evaluate(sac, eval_env, b, args.eval_seed, args.eval_targets, eval_env.horizon)
        with torch.no_grad():
            fit = float((torch.tanh(sac.actor((x - sac.norm_mean) / sac.norm_scale)[:, :b.shape[1]]) @ b_t - y).pow(2).mean())
        log.append({"iteration": it + 1, "samples": len(x), "loss": fit, "zero_torque_loss": float(y.pow(2).mean()),
                    "seconds": round(time.time() - started, 1),
                    "eval_success": ev[0], "eval_reached": ev[1], "eval_position_error": ev[2], "eval_rotation_error": ev[3]})
        print(f"iteration {it + 1}: {len(x)} samples, loss {fit:.2e} (zero torques: {log[-1]['zero_torque_loss']:.2e}), "
              f"{log[-1]['seconds']:.0f} s, eval success {ev[0]:.2f} "
              f"reached {ev[1]:.2f} (|d_p| {ev[2]:.3f} m, |d_r| {ev[3]:.3f} rad)", flush=True)
        state = {"sac": sac.state(), "log": log, "args": vars(args), "distilled": True, "iteration": it + 1}
        save_atomic(torch, state, os.path.join(args.out, "checkpoint.pt"))
        if best is None or (ev[1], ev[0]) > best:  # the iteration that reaches most held-out targets (then holds most)
            best = (ev[1], ev[0])
            save_atomic(torch, state, os.path.join(args.out, "best.pt"))


def export(args):
    """The checkpoint's deterministic policy as a manisoft-mlp file: normalisation folded into the
    first layer, the hidden layers, tanh of the mean head, then the linear layer of basis()."""
    import torch
    import manisoft

    checkpoint = torch.load(args.checkpoint)
    s = checkpoint["sac"]
    high = np.asarray(manisoft.make_vec_env("reach", 1, num_threads=1).single_action_space.high)
    weights = [(v.double().numpy(), s["actor"][k.replace("weight", "bias")].double().numpy())
               for k, v in s["actor"].items() if k.endswith("weight")]
    mean, scale = s["norm_mean"].double().numpy(), s["norm_scale"].double().numpy()
    w0, b0 = weights[0]
    weights[0] = (w0 / scale, b0 - (w0 / scale) @ mean)
    profile = basis(high)
    w_last, b_last = weights[-1]
    weights[-1] = (w_last[:profile.shape[1]], b_last[:profile.shape[1]])  # the mean head
    activations = ["relu"] * (len(weights) - 1) + ["tanh"]
    weights.append((profile, np.zeros(ROWS * 3)))
    activations.append("linear")
    tmp = args.out + ".tmp"
    with open(tmp, "w") as out:
        how = "cloned from the model executor (distill)" if checkpoint.get("distilled") else "trained with SAC"
        out.write(f"manisoft-mlp 1\n# MLP executor {how}: manisoft.sac_executor export\n")
        out.write(f"layers {len(weights)}\ninput {weights[0][0].shape[1]}\n")
        for (w, b), act in zip(weights, activations):
            out.write(f"layer {w.shape[0]} {act}\n")
            for row in w:
                out.write(" ".join(f"{x:.9g}" for x in row) + "\n")
            out.write(" ".join(f"{x:.9g}" for x in b) + "\n")
    os.replace(tmp, args.out)
    print(f"wrote {args.out}: {len(weights)} layers, {weights[0][0].shape[1]} inputs, {ROWS * 3} outputs")


def curves(args):
    """Each run's evaluations (held-out targets, the deterministic policy at every control step)
    against its training time: success (held 100 control steps) and reached (the paper's criterion)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    import torch
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.8), sharey=True)
    for run in args.runs:
        log = [e for e in torch.load(os.path.join(run, "checkpoint.pt"))["log"] if "eval_success" in e]
        minutes = [e["seconds"] / 60 for e in log]
        name = os.path.basename(os.path.normpath(run))
        axes[0].plot(minutes, [100 * e["eval_success"] for e in log], marker=".", label=name)
        axes[1].plot(minutes, [100 * e["eval_reached"] for e in log], marker=".", label=name)
    for ax, title in ((axes[0], "success: within 0.03 m / 0.3 rad, held 100 control steps"),
                      (axes[1], "reached: within 0.03 m / 0.3 rad once (the paper's criterion)")):
        ax.axhline(54, color="gray", linestyle="--", label="paper's SAC executor, reached (54%)")
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("training time (minutes, this 2-core machine)")
        ax.set_ylim(-2, 100)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("% of the held-out table targets (reach_eval seed 7)")
    handles, labels = axes[1].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=8)
    fig.suptitle("Learned executors on the reach benchmark (deterministic policy, a decision every control step)")
    fig.tight_layout(rect=(0, 0.1, 1, 1))
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}")


def main(argv=None):
    p = argparse.ArgumentParser(description="The paper's SAC-trained executor: train, export, plot")
    sub = p.add_subparsers(dest="command", required=True)
    t = sub.add_parser("train", help="train (checkpoints in --out; --resume continues)")
    t.add_argument("--out", required=True, help="run folder (checkpoint.pt)")
    t.add_argument("--minutes", type=float, help="stop after this much training time (at a round's end)")
    t.add_argument("--rounds", type=int, help="stop after this many rounds (envs x 1500 control steps each)")
    t.add_argument("--stop-after", type=int, help="write a checkpoint and stop after this round (to test --resume)")
    t.add_argument("--resume", action="store_true", help="continue from --out's checkpoint")
    t.add_argument("--init", help="start from this checkpoint's networks (post-training, e.g. with R_s, or a distilled actor)")
    t.add_argument("--init-log-std", type=float, help="with --init: the actor's log standard deviation, fixed to this at the start")
    t.add_argument("--init-alpha", type=float, default=1.0, help="with --init: the entropy temperature to start from (default 1)")
    t.add_argument("--actor-delay", type=int, default=0, help="updates of the critics alone before the actor learns (default 0)")
    t.add_argument("--anchor", type=float, default=0.0,
                   help="with --init: hold the actor near the initial one, this weight on the squared distance of their actions "
                        "(the critic's term normalised by its scale, as TD3+BC; default 0: plain SAC)")
    t.add_argument("--envs", type=int, default=32, help="arms stepped together (default 32)")
    t.add_argument("--threads", type=int, default=2, help="environment threads (default 2)")
    t.add_argument("--torch-threads", type=int, default=1, help="PyTorch threads (default 1)")
    t.add_argument("--horizon", type=int, help="control steps an episode and a round last (default: the environment's 1500)")
    t.add_argument("--repeat", type=int, default=1, help="control steps a decision holds its torques (default 1: the control rate)")
    t.add_argument("--stability-beta", type=float, default=0.0, help="R_s's beta (default 0: R_d alone, the paper's first phase)")
    t.add_argument("--hidden", type=int, nargs="+", default=[128, 128], help="hidden layer sizes (default 128 128)")
    t.add_argument("--lr", type=float, default=3e-4, help="Adam learning rate (the paper's 3e-4)")
    t.add_argument("--actor-lr", type=float, help="the actor's learning rate (default: --lr; lower to post-train an --init policy gently)")
    t.add_argument("--batch", type=int, default=256, help="minibatch (the paper's 256)")
    t.add_argument("--gamma", type=float, default=0.99, help="discount per decision (default 0.99)")
    t.add_argument("--tau", type=float, default=0.005, help="target networks' Polyak factor")
    t.add_argument("--updates", type=float, default=0.25, help="gradient updates per decision of the batch, may be below 1 (default 0.25)")
    t.add_argument("--warmup", type=int, default=10000, help="uniform random decisions before learning (default 10000)")
    t.add_argument("--buffer", type=int, default=1000000, help="replay capacity in decisions (default 1e6)")
    t.add_argument("--eval-every", type=int, default=10, help="rounds between evaluations (default 10)")
    t.add_argument("--eval-targets", type=int, default=32, help="held-out targets of an evaluation (default 32)")
    t.add_argument("--eval-seed", type=int, default=7, help="their reach_eval seed (default 7)")
    t.add_argument("--checkpoint-minutes", type=float, default=5.0, help="minutes between checkpoints (default 5)")
    t.add_argument("--seed", type=int, default=0, help="training seed (episodes, networks, exploration)")
    d = sub.add_parser("distill", help="behaviour cloning of the model executor with DAgger (checkpoint in --out)")
    d.add_argument("--out", required=True)
    d.add_argument("--iterations", type=int, default=8, help="DAgger iterations (default 8)")
    d.add_argument("--targets", type=int, default=300, help="targets (episodes) an iteration (default 300)")
    d.add_argument("--stride", type=int, default=3, help="record every k-th control step (default 3)")
    d.add_argument("--noise", type=float, default=2.0, help="N m of Gaussian noise on the executor's torques in iteration 0 (default 2)")
    d.add_argument("--epochs", type=int, default=8, help="passes over the recorded samples per iteration (default 8)")
    d.add_argument("--horizon", type=int, default=600, help="control steps a training episode (default 600: the reach and the first of the hold)")
    d.add_argument("--hidden", type=int, nargs="+", default=[256, 256, 256], help="hidden layer sizes (default 256 256 256)")
    d.add_argument("--lr", type=float, default=5e-4)
    d.add_argument("--batch", type=int, default=256)
    d.add_argument("--threads", type=int, default=2, help="evaluation threads")
    d.add_argument("--torch-threads", type=int, default=1)
    d.add_argument("--eval-targets", type=int, default=64)
    d.add_argument("--eval-seed", type=int, default=7)
    d.add_argument("--seed", type=int, default=0)
    e = sub.add_parser("export", help="write a checkpoint's policy as an MLP executor weight file")
    e.add_argument("checkpoint")
    e.add_argument("out")
    c = sub.add_parser("curves", help="plot runs' evaluations against training time (PNG)")
    c.add_argument("out")
    c.add_argument("runs", nargs="+", help="run folders (train or distill --out)")
    args = p.parse_args(argv)
    {"train": train, "distill": distill, "export": export, "curves": curves}[args.command](args)


if __name__ == "__main__":
    main()
