import pytest
from mkdocs.exceptions import PluginError

RESULTS = """# Some benchmark

| a | b |
|---|---|
| 1 | 2 |

## Section one

Text.

| c |
|---|
| 3 |

| d |
|---|
| 4 |

### Inside one

| e |
|---|
| 5 |

## Section two

| f |
|---|
| 6 |
"""


@pytest.mark.parametrize(
    ("page", "site_page", "target", "link"),
    [
        ("README.md", "index.md", "docs/simulator.md", "simulator.md"),
        ("README.md", "index.md", "docs/figures/rolling.gif", "figures/rolling.gif"),
        ("docs/benchmarks.md", "benchmarks.md", "../benchmarks/results/soak.md", "results/soak.md"),
        ("docs/benchmarks.md", "benchmarks.md", "../README.md#training-agents", "index.md#training-agents"),
        ("docs/api/physics.md", "api/physics.md", "../architecture.md", "../architecture.md"),
        ("docs/api/physics.md", "api/physics.md", "../../CHANGELOG.md", "../changelog.md"),
        ("benchmarks/results/soak.md", "results/soak.md", "soak.png", "soak.png"),
        ("docs/scenes.md", "scenes.md", "#reading-the-numbers", "#reading-the-numbers"),
        ("docs/scenes.md", "scenes.md", "https://example.org/a.md", "https://example.org/a.md"),
        ("docs/scenes.md", "scenes.md", "../ballenv/physics/scene.py", "../ballenv/physics/scene.py"),
    ],
)
def test_repository_links_point_at_site_pages(hooks, page, site_page, target, link):
    assert hooks.site_link(page, site_page, target) == link


def test_links_in_code_stay(hooks):
    spans = "`[c](../README.md)` ``[`d`](../README.md)``"
    text = f"[a](../README.md) {spans}\n\n```python\nx = '[b](../README.md)'\n```\n"
    changed = hooks.outside_code(text, lambda part: hooks.site_links("docs/x.md", "x.md", part))
    assert changed == text.replace("[a](../README.md)", "[a](index.md)")


@pytest.fixture
def root(tmp_path):
    (tmp_path / "benchmarks" / "results").mkdir(parents=True)
    (tmp_path / "benchmarks" / "results" / "some.md").write_text(RESULTS)
    return tmp_path


def include(hooks, root, title, indent=""):
    text = f'Before.\n\n{indent}[the results](../benchmarks/results/some.md "{title}")\n\nAfter.\n'
    return hooks.include_tables(root, "docs/benchmarks.md", text)


@pytest.mark.parametrize(
    ("title", "cell"),
    [
        ("table 1", "| 1 | 2 |"),
        ("table 2", "| 3 |"),
        ("table 1 in Section one", "| 3 |"),
        ("table 2 in Section one", "| 4 |"),
        ("table 3 in Section one", "| 5 |"),
        ("table 1 in Inside one", "| 5 |"),
        ("table 1 in Section two", "| 6 |"),
    ],
)
def test_a_table_link_is_replaced_by_the_table(hooks, root, title, cell):
    text = include(hooks, root, title)
    table = text.split("\n\n")[1].splitlines()
    assert table[2] == cell
    assert len(table) == 3
    assert "*[benchmarks/results/some.md](../benchmarks/results/some.md)*" in text
    assert text.startswith("Before.\n\n") and text.endswith("\n\nAfter.\n")


def test_an_indented_table_link_gives_an_indented_table(hooks, root):
    text = include(hooks, root, "table 1 in Section two", indent="  ")
    assert "\n  | f |\n  |---|\n  | 6 |\n\n  *[" in text


def test_a_plain_link_stays(hooks, root):
    text = '[the results](../benchmarks/results/some.md) and [x](../benchmarks/results/some.md "tab")\n'
    assert hooks.include_tables(root, "docs/benchmarks.md", text) == text


@pytest.mark.parametrize(
    ("title", "error"),
    [
        ("table 6", "has 5 table"),
        ("table 3 in Section two", "has 1 table"),
        ("table 1 in No such section", "no heading 'No such section'"),
    ],
)
def test_a_table_link_that_finds_no_table_stops_the_build(hooks, root, title, error):
    with pytest.raises(PluginError, match=error):
        include(hooks, root, title)


def test_a_table_link_to_a_missing_file_stops_the_build(hooks, root):
    with pytest.raises(PluginError, match="no such file"):
        hooks.include_tables(root, "docs/b.md", '[r](../benchmarks/results/none.md "table 1")')


def test_a_results_page_gets_a_title_the_script_and_its_plots(hooks, root):
    (root / "benchmarks" / "some.py").write_text("")
    (root / "benchmarks" / "results" / "some.png").write_bytes(b"")
    (root / "benchmarks" / "results" / "some_more.png").write_bytes(b"")
    page = hooks.results_page(root, "benchmarks/results/some.md", "| a |\n|---|\n| 1 |\n")
    note = "*`benchmarks/results/some.md`, written by `python benchmarks/some.py`.*"
    plots = "![some](some.png)\n\n![some_more](some_more.png)\n"
    assert page == f"# Some\n\n{note}\n\n| a |\n|---|\n| 1 |\n\n{plots}"
    titled = hooks.results_page(root, "benchmarks/results/some.md", RESULTS)
    assert titled.startswith(f"# Some benchmark\n\n{note}\n\n| a | b |\n")
