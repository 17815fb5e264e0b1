"""Optional dependencies: a missing extra's ImportError says what needs it and what to install."""

import pytest

from ballenv.extras import optional_module


def test_an_installed_module_is_returned():
    assert optional_module("json", "reading", "render", "json").dumps([1]) == "[1]"


def test_a_missing_module_names_its_user_extra_and_package():
    with pytest.raises(ImportError, match=r"MP4 video needs no-such-pkg: pip install 'ballenv\[render\]'"):
        optional_module("no_such_module_here", "MP4 video", "render", "no-such-pkg")
