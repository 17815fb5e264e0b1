"""numba's error messages as plain text under its default colour scheme
(``ballenv.physics.base.error_text``)."""

from numba.core import config, errors
from numba.core.typing import typeof

from ballenv.physics.base import error_text, jit  # noqa: F401  (jit installs it)


def test_numbas_errors_carry_their_text_without_terminal_codes():
    assert config.COLOR_SCHEME == "no_color"
    error = errors.TypingError("No implementation of function getitem")
    assert str(error) == "No implementation of function getitem"
    assert "\x1b" not in typeof._termcolor.errmsg("a message")  # typeof's own handle, the same scheme
    assert typeof._termcolor is errors.termcolor()


def test_a_chosen_colour_scheme_is_left_alone(monkeypatch):
    scheme = errors.termcolor()
    monkeypatch.delattr(scheme, "_markup", raising=False)  # numba's own markup
    monkeypatch.setattr(config, "COLOR_SCHEME", "dark_bg")
    error_text.install()
    assert "_markup" not in vars(scheme)
    monkeypatch.setattr(config, "COLOR_SCHEME", "no_color")
    error_text.install()
    assert scheme._markup is error_text._plain
