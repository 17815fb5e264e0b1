"""How a bounce's apex answers the pump's amplitude in the pressure mode, and how much of the right
amplitude the ball's observed state tells.

    python benchmarks/pump_response.py [--episodes 30]   # writes benchmarks/results/pump_response.md

The env is InflatedBall-v3's pressure mode (fast preset), played by ``agents.lookahead.LookaheadPump``:
at the start and after each flight apex it tries 41 amplitudes ``u`` in [-0.3, 0.3] with the pump's
timing (``+u`` on the ground and below the tuned landing height, ``-u`` above) on copies of the
simulator and keeps the best. Each such decision gives the signed relative error ``(h - h_t) / h_t``
of the next apex after a landing as a function of ``u``. Reported:

* one decision's response curve;
* over all decisions: ``u*``, the amplitude where the response crosses zero (linear between the
  two candidates around it), the slope ``dh/du / h_t`` there, and the scatter of ``u*`` left by
  least-squares fits on what the scripted pump and a ball-as-body agent observe (last apex error,
  target, horizontal velocity, pressure); ``slope x residual`` is the apex error such a fit leaves;
* the same scatter left out of sample by a small network (:func:`network_residual_sd`: 64-64
  units, five-fold cross-validated) on the body's numbers, with and without where within its
  control step the ball will land (``agents.wrappers.landing_phase``), and on all of them;
* the held-out scores (episodes from seed 10,000, ``agents.evaluate``) of the lookahead, of the
  tuned scripted pump, and of :class:`NetworkPump`: the pump's timing with each bounce's amplitude
  from such a network, trained on the lookahead's decisions of as many training episodes (seeds
  from 0), the body's numbers with and without the landing phase.
"""

import argparse
import os
import pathlib
import sys

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

from ballenv.files import write_text  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import ballenv  # noqa: E402, F401  (registers the env)
from agents.evaluate import DEFAULT_SEED, evaluate  # noqa: E402
from agents.imitation import regress  # noqa: E402
from agents.lookahead import LookaheadPump, zero_crossing  # noqa: E402
from agents.study import summarise, table  # noqa: E402
from agents.wrappers import landing_phase  # noqa: E402

RESULT = ROOT / "benchmarks" / "results" / "pump_response.md"
KWARGS = {"action_mode": "pressure"}  # the env's defaults: the task the agents train on
BODY = ("last apex error", "target", "horizontal velocity", "pressure")  # what the pump sees
SHAPE = (
    "spin", "rotation phase (cos, sin)", "shape modes 2, 3", "breathing (radius, its rate)",
    "landing time within the control step (cos, sin)",
)  # what only the nodes, or the clock, tell  # fmt: skip


class RecordedLookahead(LookaheadPump):
    """The lookahead, keeping at each decision the observed features and the response curve."""

    def __init__(self, env):
        super().__init__(env)
        self.structure = env.unwrapped.observation_structure
        self.config = env.unwrapped.config
        self.rows, self.curves = [], []

    def act(self, obs):
        self.obs = obs  # what the decision sees, if this step makes one (plan)
        return super().act(obs)

    def plan(self):
        amplitude = super().plan()
        if np.isfinite(self.candidate_errors).all():
            self.rows.append(features(self.obs, self.structure, self.config.control_dt, self.config.gravity))
            self.curves.append(self.candidate_errors.copy())
        return amplitude


def features(obs, structure, dt, g):
    """The decision's features: BODY (4 numbers), then SHAPE (1 + 2 + 2 + 2 + 2): the ring's spin
    (rad/s), its rotation phase ``N theta`` within one node spacing, the amplitudes of its radius'
    modes 2 and 3 relative to its mean, its mean radius (m) and mean radial velocity (m/s) (nodes
    relative to the centre of mass), and where in its control step ``dt`` (s) the ball will land
    (``agents.wrappers.landing_phase``, ``g`` in m/s^2), as its cosine and sine."""
    target = obs[structure["target_height"]][0]
    body = [
        (target - obs[structure["last_apex"]][0]) / target, target,
        obs[structure["centre_of_mass_velocity"]][0], obs[structure["pressure"]][0],
    ]  # fmt: skip
    xy = obs[structure["node_position"]].reshape(-1, 2).astype(float)
    v = obs[structure["node_velocity"]].reshape(-1, 2).astype(float)
    r2 = (xy**2).sum(axis=1)
    spin = np.mean((xy[:, 0] * v[:, 1] - xy[:, 1] * v[:, 0]) / r2)
    phase = np.angle(np.mean(np.exp(1j * len(xy) * np.arctan2(xy[:, 1], xy[:, 0]))))
    r = np.sqrt(r2)
    radius = np.abs(np.fft.rfft(r))
    grid = landing_phase(obs, structure, dt, g)
    shape = [spin, np.cos(phase), np.sin(phase), radius[2] / radius[0], radius[3] / radius[0]]
    return body + shape + [r.mean(), np.mean((xy * v).sum(axis=1) / r), np.cos(grid), np.sin(grid)]


def decisions(episodes, seed=DEFAULT_SEED):
    """The lookahead's score over ``episodes`` episodes from ``seed`` (default: the held-out ones),
    and (observed features, signed response over the amplitudes) of each of its decisions, and the
    amplitudes."""
    made = []
    score = evaluate(lambda env: made.append(RecordedLookahead(env)) or made[-1], KWARGS, episodes, seed)
    policy = made[-1]
    return score, np.array(policy.rows), np.array(policy.curves), policy.values


def zero_crossings(curves, amplitudes):
    """Per decision: ``agents.lookahead.zero_crossing`` of its response (u*, slope; NaN where it
    does not cross)."""
    u_star, slope = np.array([zero_crossing(c, amplitudes) for c in curves]).T
    return u_star, slope


BODY_COLUMNS = list(range(len(BODY)))  # columns of features(): the body's numbers
LANDING_COLUMNS = BODY_COLUMNS + [11, 12]  # and the landing phase (cos, sin)
NETWORK_INPUTS = {
    "last apex error, target, horizontal velocity, pressure": BODY_COLUMNS,
    "the same and the landing time within the control step (cos, sin)": LANDING_COLUMNS,
    "all of the above": list(range(len(BODY) + 9)),
}  # label -> columns of features()
NETWORK_PUMPS = {"network pump, body": BODY_COLUMNS, "network pump, body + landing": LANDING_COLUMNS}
FOLDS = 5


def fit_network(x, y, seed=0):
    """A 64-64 tanh network fitted to ``y`` (n,) from ``x`` (n, k), both standardised here, by
    ``agents.imitation.regress`` (full-batch Adam, learning rate 1e-3, weight decay 1e-4, stopped
    early on a sixth of the samples held back). Returns ``predict(x) -> y``."""
    import torch

    torch.manual_seed(seed)
    x_mean, x_sd, y_mean, y_sd = x.mean(axis=0), x.std(axis=0) + 1e-12, y.mean(), y.std()
    inputs = torch.tensor((x - x_mean) / x_sd, dtype=torch.float32)
    targets = torch.tensor((y - y_mean) / y_sd, dtype=torch.float32)[:, None]
    net = torch.nn.Sequential(
        torch.nn.Linear(x.shape[1], 64), torch.nn.Tanh(), torch.nn.Linear(64, 64), torch.nn.Tanh(),
        torch.nn.Linear(64, 1),
    )  # fmt: skip
    regress(
        list(net.parameters()), lambda rows: ((net(inputs[rows]) - targets[rows]) ** 2).mean(), len(y), seed
    )

    def predict(z):
        with torch.no_grad():
            scaled = torch.tensor((np.atleast_2d(z) - x_mean) / x_sd, dtype=torch.float32)
            return net(scaled).numpy()[:, 0] * y_sd + y_mean

    return predict


def network_residual_sd(u_star, features):
    """Standard deviation of ``u_star`` left out of sample by :func:`fit_network` on ``features``:
    each of ``FOLDS`` random parts predicted by the network fitted to the others."""
    parts = np.array_split(np.random.default_rng(0).permutation(len(u_star)), FOLDS)
    predicted = np.empty(len(u_star))
    for k, part in enumerate(parts):
        rest = np.concatenate([p for j, p in enumerate(parts) if j != k])
        predicted[part] = fit_network(features[rest], u_star[rest])(features[part])
    return float(np.std(u_star - predicted))


class NetworkPump(LookaheadPump):
    """The pump's timing with each bounce's amplitude from a network of the observed ``features``
    (``columns`` of :func:`features`), decided when the lookahead decides (the episode's start and
    after each flight apex). It reads nothing of the simulator but that apex event."""

    def __init__(self, env, predict, columns, label):
        super().__init__(env, candidates=2)
        self.structure = env.unwrapped.observation_structure
        self.config = env.unwrapped.config
        self.predict, self.columns, self.name = predict, columns, label
        self.obs = None

    def act(self, obs):
        self.obs = obs
        return super().act(obs)

    def plan(self):
        x = features(self.obs, self.structure, self.config.control_dt, self.config.gravity)
        return float(np.clip(self.predict(np.asarray(x)[self.columns])[0], -0.3, 0.3))


def network_pumps(episodes):
    """Held-out scores of :class:`NetworkPump` trained on the lookahead's decisions of ``episodes``
    training episodes (seeds from 0), on the body's numbers with and without the landing phase."""
    _, rows, curves, amplitudes = decisions(episodes, seed=0)
    u_star, _ = zero_crossings(curves, amplitudes)
    ok = np.isfinite(u_star)
    scores = []
    for label, columns in NETWORK_PUMPS.items():
        predict = fit_network(rows[ok][:, columns], u_star[ok])
        pump = lambda env, p=predict, c=columns, n=label: NetworkPump(env, p, c, n)  # noqa: E731
        scores.append(evaluate(pump, KWARGS, episodes))
    return scores


def residual_sd(u_star, features):
    """Standard deviation of ``u_star`` left by a least-squares fit on ``features`` (and a constant)."""
    design = (
        np.column_stack([np.ones(len(u_star)), *features.T]) if features.size else np.ones((len(u_star), 1))
    )
    coef, *_ = np.linalg.lstsq(design, u_star, rcond=None)
    return float(np.std(u_star - design @ coef))


def report(rows, curves, amplitudes, scores):
    u_star, slope = zero_crossings(curves, amplitudes)
    ok = np.isfinite(u_star)
    u, x, s = u_star[ok], rows[ok], float(np.median(slope[ok]))
    shown = np.arange(0, len(amplitudes), 4)
    lines = [
        "# The pump's amplitude and the next apex (InflatedBall-v3, pressure mode)",
        "",
        "One decision (seed 10,000, the first): signed error of the next apex after a landing,",
        "",
        "| u | " + " | ".join(f"{amplitudes[k]:+.2f}" for k in shown) + " |",
        "|---|" + "---:|" * len(shown),
        "| (h - h_t) / h_t | " + " | ".join(f"{curves[0][k]:+.3f}" for k in shown) + " |",
        "",
        f"Over {len(curves)} decisions of {scores['episodes']} episodes ({ok.sum()} cross zero): "
        f"u* mean {u.mean():.3f}, sd {u.std():.3f}; slope (median) {s:.2f} per unit u.",
        "",
        "| fit of u* on | residual sd of u* | apex error it leaves (slope x sd) |",
        "|---|---:|---:|",
    ]
    fits = [(k, ", ".join(BODY[:k]) or "a constant") for k in range(len(BODY) + 1)]
    fits.append((x.shape[1], "all of these and the shape: " + ", ".join(SHAPE)))
    for k, label in fits:
        sd = residual_sd(u, x[:, :k])
        lines.append(f"| {label} | {sd:.4f} | {s * sd:.3f} |")
    lines += [
        "",
        f"The same out of sample, by a 64-64 network ({FOLDS}-fold cross-validated, `network_residual_sd`):",
        "",
        "| network of u* on | residual sd of u* | apex error it leaves (slope x sd) |",
        "|---|---:|---:|",
    ]
    for label, columns in NETWORK_INPUTS.items():
        sd = network_residual_sd(u, x[:, columns])
        lines.append(f"| {label} | {sd:.4f} | {s * sd:.3f} |")
    lines += [
        "",
        f"Held-out episodes from seed 10,000 (``agents.evaluate``): {scores['episodes']} each; the network "
        "pumps learned from the lookahead's decisions in as many training episodes (seeds from 0).",
        "",
    ]
    lines.append(table([summarise(score.policy, [score]) for score in scores["rows"]]))
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--episodes", type=int, default=30)
    args = parser.parse_args()
    lookahead, rows, curves, amplitudes = decisions(args.episodes)
    heuristic = evaluate("heuristic", KWARGS, args.episodes)
    scores = {"episodes": args.episodes, "rows": [lookahead, heuristic, *network_pumps(args.episodes)]}
    text = report(rows, curves, amplitudes, scores)
    write_text(RESULT, text)
    print(text)


if __name__ == "__main__":
    main()
