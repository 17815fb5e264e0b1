"""``python -m ballenv.render``: the frame strip, written outside the tracked files by default."""

import pathlib

import numpy as np
import pygame

from ballenv.render import main

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_the_frame_strip_goes_to_out_by_default_not_over_a_tracked_file(tmp_path, monkeypatch, capsys):
    # the default was docs/env.png: a bare `python -m ballenv.render` rewrote the README's picture
    monkeypatch.chdir(tmp_path)
    main([])
    written = tmp_path / "out" / "env.png"
    assert capsys.readouterr().out.strip() == "out/env.png"
    assert "out/" in (ROOT / ".gitignore").read_text().split()  # git keeps nothing there
    image = pygame.surfarray.array3d(pygame.image.load(str(written)))
    assert image.shape == (5 * 480, 2 * 480, 3)  # five frames across, both action modes
    assert len(np.unique(image.reshape(-1, 3), axis=0)) > 3
