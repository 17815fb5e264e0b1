"""Options for the Newton linear solve of the 3-D shell, measured on the same systems: the envelope
Cholesky after reverse Cuthill-McKee with the gas's rank-one term by Sherman-Morrison (kept,
ballenv/shell/solve/envelope.py), Jacobi-preconditioned CG on the element matrices assembled as a
block-sparse matrix (ballenv/shell/solve/cg.py, blocks.py; the assembly is in its time), and a dense LU
(LAPACK through NumPy's np.linalg.solve) as the reference.

    python benchmarks/shell_linear_solve.py     # writes benchmarks/results/shell_linear_solve.md

Systems: the default ball (Shell(): R = 0.12 m, E = 5 MPa, nu = 0.45, h = 3 mm, p = 55 kPa,
isothermal gas) at its inflated equilibrium, on icospheres of 162, 642 and 2562 vertices.
"static": the Hessian K with the six components of the determinate support fixed (what
ballenv.shell.rest.equilibrium solves); "dynamic": M / dt^2 + K with dt = 1e-3 s and 1e-4 s (what an
implicit step solves). CG stops at a residual of 1e-8 of the right-hand side. Times are medians of
repeated runs, numba warm, OPENBLAS_NUM_THREADS=1; the ratios divide by the dense solve's time in the
same process.
Also measured: the first run of the shell's kernels with an empty numba cache, in a new process.
"""

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pathlib  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from ballenv.files import write_text  # noqa: E402
from ballenv.shell import Shell, equilibrium  # noqa: E402
from ballenv.shell.rest.equilibrium import determinate_support  # noqa: E402
from ballenv.shell.rest.modes import element_dofs  # noqa: E402
from ballenv.shell.skin import potential  # noqa: E402
from ballenv.shell.skin.model import build_model, build_workspace  # noqa: E402
from ballenv.shell.solve import blocks, cg, envelope  # noqa: E402

RESULTS = pathlib.Path(__file__).parent / "results"
ROOT = pathlib.Path(__file__).resolve().parents[1]
STEPS = (1e-3, 1e-4)  # s: the dynamic systems' time steps
CG_RTOL = 1e-8
COLD_SCRIPT = """
import time
t0 = time.perf_counter()
from ballenv.shell import Shell, equilibrium, modes
equilibrium(Shell(subdivisions=1))
modes(Shell(subdivisions=1), count=8)
print(time.perf_counter() - t0)
"""


def median_time(f, repeats):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def system(subdivisions, dt):
    """(model, workspace, rank-one weight, free mask, diagonal, right-hand side, dense matrix)."""
    shell = Shell(subdivisions=subdivisions, position=(0, 0, 0))
    x = equilibrium(shell).x
    model = build_model(shell)
    ws = build_workspace(model)
    s = potential.hessian(model, ws, x)
    if dt:
        free = np.ones(x.shape, dtype=np.bool_)
        diagonal = np.repeat(model.mass[:, None], 3, axis=1) / dt**2
    else:
        free = determinate_support(x)
        diagonal = np.zeros_like(x)
    rhs = np.where(free, np.random.default_rng(0).standard_normal(x.shape), 0.0)
    dense = np.zeros((x.size, x.size))
    for elements, mats in ((model.triangles, ws.tri_hess), (model.hinges, ws.hinge_hess)):
        d = element_dofs(elements)
        np.add.at(dense, (d[:, :, None], d[:, None, :]), mats)
    u = ws.dvol.reshape(-1)
    dense += s * np.outer(u, u) + np.diag(diagonal.reshape(-1))
    fixed = ~free.reshape(-1)
    dense[fixed, :] = 0.0
    dense[:, fixed] = 0.0
    dense[fixed, fixed] = 1.0
    return model, ws, s, free, diagonal, rhs, dense


def measure(subdivisions, dt):
    model, ws, s, free, diagonal, rhs, dense = system(subdivisions, dt)
    n = rhs.size
    repeats = max(1, 2000 // n)
    t_dense = median_time(lambda: np.linalg.solve(dense, rhs.reshape(-1)), max(1, repeats // 4))
    exact = np.linalg.solve(dense, rhs.reshape(-1)).reshape(rhs.shape)
    t_order = median_time(lambda: envelope.build_envelope(len(model.rest), model.triangles, model.hinges), 1)
    env = envelope.build_envelope(len(model.rest), model.triangles, model.hinges)
    out, z = np.zeros_like(rhs), np.zeros_like(rhs)

    def factor():
        envelope.assemble(env, model.triangles, ws.tri_hess, model.hinges, ws.hinge_hess, diagonal, free)
        assert envelope.cholesky(env)

    factor()
    t_factor = median_time(factor, repeats)
    t_solve = median_time(lambda: envelope.solve_rank_one(env, free, s, ws.dvol, rhs, out, z), 5 * repeats)
    err_env = float(np.abs(out - exact).max() / np.abs(exact).max())
    x_cg, work = np.zeros_like(rhs), np.zeros((4,) + rhs.shape)
    op = cg.make_operator(blocks.block_pattern(len(model.rest), model.triangles, model.hinges), 1)
    for c in range(3):
        op.vertex_blocks[:, c, c] = diagonal[:, c]
    op.vectors[0] = ws.dvol
    op.weights[0] = s

    def assemble_and_solve():
        blocks.assemble(op.pattern, ws.tri_hess, ws.hinge_hess, 1.0, op.values)
        return cg.pcg(op, free, rhs, x_cg, work, CG_RTOL, 100_000)

    iterations = assemble_and_solve()
    t_cg = median_time(assemble_and_solve, repeats)
    err_cg = float(np.abs(x_cg - exact).max() / np.abs(exact).max())
    return {
        "vertices": len(model.rest), "dofs": n, "envelope": env.values.size, "dense": t_dense,
        "order": t_order, "factor": t_factor, "solve": t_solve, "err_env": err_env,
        "cg": t_cg, "cg_iterations": iterations, "err_cg": err_cg,
    }  # fmt: skip


def cold_compile_seconds():
    """Wall time (s) of a new process's first equilibrium and modes with an empty numba cache."""
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache, "PYTHONPATH": str(ROOT)}
        out = subprocess.run(
            [sys.executable, "-c", COLD_SCRIPT], env=env, capture_output=True, text=True, check=True
        )
        return float(out.stdout.strip().splitlines()[-1])


def table(rows, kind):
    lines = [
        f"**{kind}**",
        "",
        "| vertices | DOFs | envelope entries | dense LU (ms) | envelope: factor + solve (ms) | ratio | "
        "ordering, once per mesh (ms) | CG (ms) | CG iterations | ratio | error envelope / CG |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    for r in rows:
        env_total = r["factor"] + r["solve"]
        lines.append(
            f"| {r['vertices']} | {r['dofs']} | {r['envelope']:,} | {1e3 * r['dense']:.1f} | "
            f"{1e3 * r['factor']:.1f} + {1e3 * r['solve']:.2f} | {env_total / r['dense']:.3f} | "
            f"{1e3 * r['order']:.0f} | {1e3 * r['cg']:.1f} | {r['cg_iterations']} | "
            f"{r['cg'] / r['dense']:.3f} | "
            f"{r['err_env']:.0e} / {r['err_cg']:.0e} |"
        )
    return lines


def main():
    RESULTS.mkdir(exist_ok=True)
    lines = ["# The shell's linear solve", ""]
    for dt in (0.0, *STEPS):
        rows = [measure(k, dt) for k in (2, 3, 4)]
        kind = f"dynamic: M / dt^2 + K, dt = {dt:g} s" if dt else "static: K, determinate support"
        lines += table(rows, kind) + [""]
        print("\n".join(lines), flush=True)
    cold = cold_compile_seconds()
    lines.append(f"First equilibrium and modes of a 42-vertex ball with an empty numba cache: {cold:.0f} s.")
    write_text(RESULTS / "shell_linear_solve.md", "\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
