"""``ballenv.physics`` imports, builds and names its effects with gymnasium, pygame, torch and
matplotlib blocked (the simulator needs only numpy, numba and tqdm)."""

import subprocess
import sys
import textwrap

BLOCKED = ("gymnasium", "pygame", "torch", "matplotlib", "stable_baselines3")

SCRIPT = textwrap.dedent(
    f"""
    import sys

    class Blocker:
        def find_spec(self, name, path=None, target=None):
            if name.split(".")[0] in {BLOCKED!r}:
                raise ModuleNotFoundError(f"No module named {{name!r}} (blocked)", name=name)
            return None

    sys.meta_path.insert(0, Blocker())
    import ballenv.physics as physics
    from ballenv.physics.build import build_model, scene_effects

    ground = physics.Ground(friction=0.5)
    scene = physics.Scene(rings=[physics.Ring(n_nodes=8)], grounds=[ground], damping=1.0)
    build_model(scene)
    assert scene_effects(scene)[-2:] == ("ground", "friction"), scene_effects(scene)
    loaded = sorted(m for m in sys.modules if m.split(".")[0] in {BLOCKED!r})
    assert not loaded, loaded
    print("ok")
    """
)


def test_physics_imports_without_gymnasium_pygame_torch_matplotlib():
    out = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip() == "ok"
