"""The scenes' figures (matplotlib, the ``plot`` extra): ``plot(result, path)`` writes a PNG."""

import math

import numpy as np

from ..extras import optional_module
from .library import least_curvature

DPI = 80


def _plt():
    optional_module("matplotlib", "the scene figures", "plot", "matplotlib").use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _closed(x):
    return np.vstack([x, x[:1]])


def _ground_line(ax, ground, xlim):
    xs = np.array(xlim)
    ax.plot(xs, ground.height + (xs - ground.x) * math.tan(ground.angle), color="0.3", lw=1.5)


def plot(result, path):
    """Write the figure of ``result`` (a :class:`~ballenv.scenes.SceneResult`) to ``path``."""
    plt = _plt()
    fig = PLOTS[result.name](plt, result)
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


def _bounce_vs_pressure(plt, res):
    m = res.metrics
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    p = np.array(m["pressure_Pa"]) / 1e3
    for (label, apex), colour in zip(m["apex_m"].items(), ("k", "tab:blue"), strict=False):
        axes[0].plot(p, apex, "o-", color=colour, label=f"E = {label}")
    axes[0].set_xlabel("inflation pressure (kPa gauge)")
    axes[0].set_ylabel("first apex of the centre (m)")
    axes[0].set_title("bounce height vs pressure (drop from 1 m)")
    axes[0].legend()
    for label in res.animate:
        tr = res.trajectories[label]
        line = axes[1].plot(tr.t, tr.centre_of_mass()[:, 0, 1], lw=1, label=label)
        apex = tr.apexes()
        axes[1].plot(apex[:, 0], apex[:, 1], "o", ms=4, color=line[0].get_color())
    axes[1].set_xlabel("t (s)")
    axes[1].set_ylabel("centre height (m)")
    axes[1].set_title("the softest and hardest-pumped E = 10 MPa balls")
    axes[1].legend(fontsize=8)
    return fig


def _bounce_strip(plt, res):
    tr = res.trajectories["bounce"]
    frames = res.metrics["frame_indices"]
    fig, ax = plt.subplots(figsize=(11, 2.6))
    step = 0.24
    for j, k in enumerate(frames):
        x = tr.x[k, 0].copy()
        x[:, 0] += j * step - x[:, 0].mean()
        ax.plot(*_closed(x).T, color="tab:red", lw=1.2)
        f = tr.contact_force[k, 0]
        for xi, fi in zip(x, f, strict=True):
            if fi[1] > 0:
                ax.plot([xi[0], xi[0]], [xi[1], xi[1] + 4e-4 * fi[1]], color="tab:blue", lw=0.8)
        ax.text(j * step, -0.05, f"{tr.t[k] * 1e3:.0f} ms", ha="center", fontsize=8)
    ax.axhline(0.0, color="0.3", lw=1.5)
    ax.set_aspect("equal")
    ax.set_ylim(-0.07, None)
    ax.axis("off")
    ax.set_title(
        f"one bounce, frames every {res.parameters['frame_interval'] * 1e3:.0f} ms "
        f"(contact {res.metrics['contact_duration_s'] * 1e3:.1f} ms, "
        f"largest compression {res.metrics['max_compression'] * 100:.0f} %; blue: ground reaction)"
    )
    return fig


def _deformation(plt, res):
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
    for ax, label in zip(axes, res.animate, strict=True):
        tr = res.trajectories[label]
        m = res.metrics[label]
        k = m["frame_index"]
        for j, style in ((0, dict(color="0.6", ls="--", lw=1)), (k, dict(color="tab:red", lw=1.8))):
            x = tr.x[j, 0].copy()
            x[:, 1] -= x[:, 1].min()
            ax.plot(*_closed(x).T, **style)
        ax.axhline(0.0, color="0.3", lw=1.5)
        ax.set_aspect("equal")
        ax.set_title(
            f"{label}: p R^3/EI = {m['p_R3_over_EI']:.3g}\n"
            f"aspect {m['aspect']:.2f}, curvature top {m['curvature_top']:.2f} side "
            f"{m['curvature_side']:.2f}",
            fontsize=10,
        )
        ax.set_xlabel("x (m)")
    axes[0].set_ylabel("height (m)")
    fig.suptitle(
        f"largest compression at {res.parameters['impact_speed']:g} m/s impact (dashed: before impact)",
        fontsize=10,
    )
    return fig


def _rolling(plt, res):
    m = res.metrics
    labels = res.animate
    fig = plt.figure(figsize=(12, 4))
    grid = fig.add_gridspec(1, len(labels) + 1, width_ratios=[1] * len(labels) + [1.4])
    slope = res.parameters["slope"]
    c, s = math.cos(slope), math.sin(slope)
    rot = np.array([[c, s], [-s, c]])  # into the slope's frame
    for j, label in enumerate(labels):
        ax = fig.add_subplot(grid[0, j])
        tr = res.trajectories[label]
        x = tr.x[-1, 0] @ rot.T
        x[:, 0] -= x[:, 0].mean()
        ax.plot(*_closed(x).T, color="tab:red", lw=1.5)
        ax.axhline(0.0, color="0.3", lw=1.5)
        ax.set_aspect("equal")
        ax.set_xlim(-0.16, 0.16)
        ax.set_ylim(-0.01, 0.22)
        ax.set_title(f"{label}\nH/D = {m['height_over_diameter'][j]:.2f}", fontsize=10)
        ax.set_xticks([])
        if j:
            ax.set_yticks([])
    ax = fig.add_subplot(grid[0, -1])
    E = np.array(m["youngs_modulus_Pa"]) / 1e6
    ax.plot(E, m["height_over_diameter"], "o-", color="tab:red")
    ax.set_xlabel("E (MPa)")
    ax.set_ylabel("rolling height / rest diameter")
    ax.set_title("height grows with E", fontsize=10)
    return fig


def _variable_inflation(plt, res):
    m = res.metrics
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for label in res.animate:
        tr = res.trajectories[label]
        axes[0].plot(tr.t, tr.centre_of_mass()[:, 0, 1], lw=1, label=label)
        axes[1].plot(tr.t, tr.pressure[:, 0] / 1e3, lw=1, label=label)
    for t in m["switch_times_s"]:
        axes[0].axvline(t, color="0.7", lw=0.8, ls=":")
        axes[1].axvline(t, color="0.7", lw=0.8, ls=":")
    axes[0].set_xlabel("t (s)")
    axes[0].set_ylabel("centre height (m)")
    axes[0].set_title("gas set at each apex: " + ", ".join(f"{p / 1e3:g}" for p in m["schedule_Pa"]) + " kPa")
    axes[0].legend()
    axes[1].set_yscale("log")
    axes[1].set_xlabel("t (s)")
    axes[1].set_ylabel("gauge pressure (kPa)")
    axes[1].set_title("pressure: each pump rings the wall; impacts raise it (gas law)", fontsize=10)
    return fig


def _slope_spin(plt, res):
    fig, ax = plt.subplots(figsize=(9, 4.5))
    for label in res.animate:
        tr = res.trajectories[label]
        com = tr.centre_of_mass()[:, 0]
        ax.plot(com[:, 0], com[:, 1], lw=1.2, label=label)
    ground = res.trajectories[res.animate[0]].scene.grounds[0]
    xlim = ax.get_xlim()
    _ground_line(ax, ground, xlim)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    rows = res.metrics["cases"]
    text = "\n".join(
        f"spin {r['spin_in_rad_per_s']:+.0f} -> {r['spin_out_rad_per_s']:+.1f} rad/s, downhill "
        f"{r['downhill_in_m_per_s']:.2f} -> {r['downhill_out_m_per_s']:+.2f} m/s"
        for r in rows
    )
    ax.set_title("centre paths after a drop on a 0.3 rad slope (friction 0.5)", fontsize=10)
    ax.text(0.02, 0.02, text, transform=ax.transAxes, fontsize=8, family="monospace")
    ax.legend(fontsize=8, loc="upper right")
    return fig


def _two_balls(plt, res):
    tr = res.trajectories["collision"]
    fig, ax = plt.subplots(figsize=(10, 3.8))
    gap = np.linalg.norm(tr.centre_of_mass()[:, 0] - tr.centre_of_mass()[:, 1], axis=1)
    touch = int(np.argmin(gap))
    picks = sorted({0, touch // 2, touch, (touch + len(tr.t) - 1) // 2, len(tr.t) - 1})
    for j, k in enumerate(picks):
        shade = 0.25 + 0.75 * j / (len(picks) - 1)
        for r, colour in ((0, (0.8, 0.25, 0.15)), (1, (0.15, 0.35, 0.8))):
            ax.plot(*_closed(tr.x[k, r]).T, color=colour, alpha=shade, lw=1.2)
        ax.text(tr.centre_of_mass()[k, 0, 0], 0.17, f"{tr.t[k] * 1e3:.0f} ms", fontsize=7, ha="center")
    m = res.metrics
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_title(
        f"two balls at {res.parameters['speed']:g} m/s each: restitution {m['restitution']:.2f}, "
        f"momentum change {m['momentum_change_relative']:.1e} of 2 m v",
        fontsize=10,
    )
    return fig


def _vibrating_plate(plt, res):
    m = res.metrics
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
    for gamma in m["gamma"]:
        h = np.array(m["apex_heights_m"][str(gamma)]) * 1e3
        phi = np.array(m["impact_phases_rad"][str(gamma)])
        axes[0].plot(np.full(len(h), gamma), h, ".", ms=3, color="k")
        axes[1].plot(np.full(len(phi), gamma), phi, ".", ms=3, color="k")
    e = m["restitution"]
    for ax in axes:
        ax.axvline(m["theory_period_doubling_at"], color="tab:red", lw=1, ls="--",
                   label=f"point particle, e = {e:.2f}: period doubling")  # fmt: skip
        if m["measured_period_doubling_at"] is not None:
            ax.axvline(
                m["measured_period_doubling_at"],
                color="tab:blue",
                lw=1,
                ls=":",
                label="ring: first non-period-1",
            )
        ax.set_xlabel("plate acceleration Gamma = A (2 pi f)^2 / g")
    gam = np.linspace(1.0, max(m["gamma"]), 200)
    phase = np.arccos(np.minimum(1.0, m["theory_period_one_from"] / gam))
    stable = gam <= m["theory_period_doubling_at"]
    axes[1].plot(
        gam[stable], phase[stable], color="tab:red", lw=1, label="point particle: period-1 impact phase"
    )
    axes[0].set_ylabel("apex of the centre above touching (mm)")
    axes[0].set_title(f"apex heights of the last 30 bounces, f = {res.parameters['frequency']:g} Hz")
    axes[1].set_ylabel("impact phase 2 pi f t mod 2 pi (rad)")
    axes[1].set_title("impact phases")
    axes[0].legend(fontsize=8)
    axes[1].legend(fontsize=8)
    return fig


def _rotating_drum(plt, res):
    rows = res.metrics["rows"]
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.5))
    froude = [r["froude"] for r in rows]
    axes[0].plot(
        froude, [r["aspect"] for r in rows], "o-", color="k", label="aspect ratio (mean of the last 1 s)"
    )
    low = [r["aspect"] - r["aspect_range"][0] for r in rows]
    high = [r["aspect_range"][1] - r["aspect"] for r in rows]
    axes[0].errorbar(froude, [r["aspect"] for r in rows], yerr=[low, high], fmt="none", color="0.5")
    axes[0].set_xlabel("Froude number Omega^2 R_d / g")
    axes[0].set_ylabel("major / minor axis")
    axes[0].set_title("ribbon loop in a rotating drum (Raux et al. 2010, qualitatively)", fontsize=10)
    twin = axes[0].twinx()
    twin.plot(froude, [math.degrees(r["centre_angle_rad"]) for r in rows], "s:", color="tab:blue", ms=4)
    twin.set_ylabel("centre's angle from the bottom (deg)", color="tab:blue")
    axes[0].legend(fontsize=8, loc="upper left")
    drum = res.parameters["drum_radius"]
    phi = np.linspace(0.0, 2.0 * math.pi, 400)
    axes[1].plot(drum * np.cos(phi), drum * np.sin(phi), color="0.3", lw=1.5)
    labels = list(res.trajectories)
    picks = list(dict.fromkeys([labels[0], labels[len(labels) // 2], labels[-1]]))
    for label, colour in zip(picks, ("k", "tab:green", "tab:red"), strict=False):
        tr = res.trajectories[label]
        k = len(tr.t) - 1
        if label == labels[-1]:  # the fastest: its most concave shape of the last second
            late = np.nonzero(tr.t > tr.t[-1] - 1.0 - 1e-9)[0]
            k = int(late[np.argmin([least_curvature(tr.x[j, 0]) for j in late])])
        axes[1].plot(
            *_closed(tr.x[k, 0]).T, color=colour, lw=1.5, label=f"{label} rad/s, t = {tr.t[k]:.2f} s"
        )
    axes[1].set_aspect("equal")
    axes[1].set_xlim(-drum * 0.4, drum * 0.8)
    axes[1].set_ylim(-drum * 1.03, -drum * 0.35)
    axes[1].set_xlabel("x (m)")
    axes[1].set_ylabel("y (m)")
    axes[1].set_title(
        "last shapes; the fastest: its most concave (drum turning counter-clockwise)", fontsize=10
    )
    axes[1].legend(fontsize=8, loc="upper left")
    return fig


PLOTS = {
    "bounce-vs-pressure": _bounce_vs_pressure,
    "bounce-strip": _bounce_strip,
    "deformation": _deformation,
    "rolling": _rolling,
    "variable-inflation": _variable_inflation,
    "slope-spin": _slope_spin,
    "two-balls": _two_balls,
    "vibrating-plate": _vibrating_plate,
    "rotating-drum": _rotating_drum,
}
