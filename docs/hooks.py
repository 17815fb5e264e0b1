"""MkDocs hooks (``hooks:`` in mkdocs.yml): the repository's markdown, as it reads on GitHub, as the site.

* Pages from files outside ``docs/`` (``on_files``): the README is the home page, the CHANGELOG a
  page, each benchmark results file (``benchmarks/results/NAME.md``, with its plots) a page, and the
  environment's page is made from the docstring of ``InflatedBallEnv``, as Gymnasium makes its
  environment pages.
* Links by repository path (``on_page_markdown``): every page links to other files by their path
  in the repository, so the links work on GitHub (the README: ``docs/simulator.md``;
  ``docs/benchmarks.md``: ``../benchmarks/results/soak.md``); ``SITE_PATHS`` maps each to its page.
* Tables written once, by the benchmarks: a line that is only a link to a results file whose title
  is ``table K`` or ``table K in HEADING`` (K counts from 1), e.g.
  ``[benchmarks/results/soak.md](../benchmarks/results/soak.md "table 1 in Random scenes")``, is a
  link on GitHub and the file's K-th table (of the section under that heading) on the site.
"""

import inspect
import posixpath
import re
import sys
from pathlib import Path

from mkdocs.exceptions import PluginError
from mkdocs.structure.files import File

RESULTS = "benchmarks/results"
ENV_PAGE = "envs/inflated_ball.md"
ENV_SOURCE = "ballenv/envs/inflated_ball.py"
SITE_PATHS = (  # repository path (prefix) -> its path on the site
    ("docs/", ""),
    ("README.md", "index.md"),
    ("CHANGELOG.md", "changelog.md"),
    (RESULTS + "/", "results/"),
)

CODE = re.compile(  # a fenced code block, or a code span
    r"^(```|~~~).*?^\1[ \t]*$|(`+)[^`\n].*?(?<!`)\2(?!`)", re.MULTILINE | re.DOTALL
)
LINK = re.compile(r"(!?\[[^\]]*\]\()([^)\s]+)(\s+\"[^\"]*\")?\)")
TABLE_LINK = re.compile(  # a line that is only [text](target "table K[ in HEADING]")
    r"^([ \t]*)\[[^\]]*\]\(([^)\s]+)\s+\"table (\d+)(?: in (.+?))?\"\)[ \t]*$", re.MULTILINE
)
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")

_repo_paths = {}  # site path of each page -> its file in the repository


def on_files(files, config):
    """Add the pages made from files outside docs/ (module doc) and remember each page's source."""
    root = Path(config.config_file_path).parent
    _repo_paths.clear()
    for file in files.documentation_pages():
        _repo_paths[file.src_uri] = "docs/" + file.src_uri
    pages = {"index.md": "README.md", "changelog.md": "CHANGELOG.md"}
    pages.update({f"results/{p.name}": f"{RESULTS}/{p.name}" for p in sorted((root / RESULTS).glob("*.md"))})
    for site_path, repo_path in pages.items():
        text = (root / repo_path).read_text()
        if repo_path.startswith(RESULTS):
            text = results_page(root, repo_path, text)
        files.append(File.generated(config, site_path, content=text))
        _repo_paths[site_path] = repo_path
    for plot in sorted((root / RESULTS).glob("*.png")):
        files.append(File.generated(config, f"results/{plot.name}", abs_src_path=str(plot)))
    files.append(File.generated(config, ENV_PAGE, content=env_page(root)))
    _repo_paths[ENV_PAGE] = "docs/" + ENV_PAGE  # made here: its links are written as from docs/
    return files


def on_page_markdown(markdown, page, config, files):
    """Put the results tables in (module doc) and point the links at the pages of the site."""
    root = Path(config.config_file_path).parent
    repo_path = _repo_paths[page.file.src_uri]
    text = outside_code(markdown, lambda part: include_tables(root, repo_path, part))
    return outside_code(text, lambda part: site_links(repo_path, page.file.src_uri, part))


def outside_code(markdown, change):
    """``markdown`` with ``change(text)`` applied to the text outside code blocks and code spans."""
    out, end = [], 0
    for block in CODE.finditer(markdown):
        out += [change(markdown[end : block.start()]), block.group(0)]
        end = block.end()
    return "".join(out + [change(markdown[end:])])


def site_path(repo_path):
    """The site's path of a repository file, or None if the site has no page or copy of it."""
    for prefix, site_prefix in SITE_PATHS:
        if repo_path == prefix or (prefix.endswith("/") and repo_path.startswith(prefix)):
            return site_prefix + repo_path[len(prefix) :]
    return None


def site_link(page_repo_path, page_site_path, target):
    """A link ``target`` written in the repository file ``page_repo_path``, as a link of the page at
    ``page_site_path``; absolute URLs, anchors and paths the site does not map stay as they are."""
    if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith(("#", "/")):
        return target
    path, hash_, anchor = target.partition("#")
    mapped = site_path(posixpath.normpath(posixpath.join(posixpath.dirname(page_repo_path), path)))
    if mapped is None:
        return target
    return posixpath.relpath(mapped, posixpath.dirname(page_site_path) or ".") + hash_ + anchor


def site_links(page_repo_path, page_site_path, text):
    """Every inline link and image of ``text`` through ``site_link``."""

    def replace(link):
        title = link.group(3) or ""
        return link.group(1) + site_link(page_repo_path, page_site_path, link.group(2)) + title + ")"

    return LINK.sub(replace, text)


def include_tables(root, page_repo_path, text):
    """Each table link of ``text`` (module doc) replaced by the table, indented as the link was,
    with the link below it (on the site it leads to the whole results file)."""

    def replace(link):
        indent, target, number, heading = link.groups()
        source = posixpath.normpath(posixpath.join(posixpath.dirname(page_repo_path), target))
        where = f"{page_repo_path}: table {number}{f' in {heading!r}' if heading else ''} of {source}"
        path = root / source
        if not path.is_file():
            raise PluginError(f"{where}: no such file")
        table = nth_table(section(path.read_text(), heading, where), int(number), where)
        caption = f"*[{source}]({target})*"
        return "\n".join(indent + line if line else "" for line in [*table, "", caption])

    return TABLE_LINK.sub(replace, text)


def section(markdown, heading, where):
    """The lines under the heading titled ``heading`` up to the next heading of its level or above
    (all lines if ``heading`` is None)."""
    lines = markdown.splitlines()
    if heading is None:
        return lines
    for i, line in enumerate(lines):
        found = HEADING.match(line)
        if found and found.group(2) == heading:
            level = len(found.group(1))
            ends = [j for j in range(i + 1, len(lines)) if heading_level(lines[j]) <= level]
            return lines[i + 1 : ends[0] if ends else len(lines)]
    raise PluginError(f"{where}: no heading {heading!r}")


def heading_level(line):
    """The level of a markdown heading line (1 for '#'); 7 for any other line."""
    found = HEADING.match(line)
    return len(found.group(1)) if found else 7


def nth_table(lines, number, where):
    """The ``number``-th (from 1) markdown table of ``lines``: its consecutive lines starting with '|'."""
    tables, current = [], []
    for line in [*lines, ""]:
        if line.lstrip().startswith("|"):
            current.append(line.strip())
        elif current:
            tables.append(current)
            current = []
    if not 1 <= number <= len(tables):
        raise PluginError(f"{where}: it has {len(tables)} table(s)")
    return tables[number - 1]


def results_page(root, repo_path, text):
    """A results file as a page: a title if it has none, which script writes it, and its plots."""
    name = Path(repo_path).stem
    script = f"benchmarks/{name}.py"
    lines = text.strip("\n").splitlines()
    title = f"# {name.replace('_', ' ').capitalize()}"
    if lines and lines[0].startswith("# "):
        title, lines = lines[0], lines[1:]
    writer = f", written by `python {script}`" if (root / script).is_file() else ""
    plots = [f"![{p.stem}]({p.name})" for p in sorted((root / RESULTS).glob(name + "*.png"))]
    body = "\n".join(lines).strip("\n")
    return "\n\n".join([title, f"*`{repo_path}`{writer}.*", body, *plots]) + "\n"


def env_page(root):
    """The page of InflatedBall-v3: the facts of its registration and spaces (from the code, as
    Gymnasium's environment pages begin), then the class docstring."""
    if str(root) not in sys.path:
        sys.path.insert(0, str(root))  # this checkout's ballenv, not an installed one
    import gymnasium

    from ballenv.envs import ENV_IDS
    from ballenv.envs.config import BallEnvConfig
    from ballenv.envs.inflated_ball import InflatedBallEnv

    rows = []
    for env_id in ENV_IDS.values():
        spec = gymnasium.spec(env_id)
        low, _ = BallEnvConfig.from_kwargs(dict(spec.kwargs)).observation_bounds()
        size = f"{low.shape[0]} values, {low.dtype}"
        rows.append(f"| `{env_id}` | `{spec.kwargs}` | {size} | {spec.max_episode_steps} |")
    return "\n".join(
        [
            "# InflatedBall-v3",
            "",
            "![InflatedBall-v3](../env.png)",
            "",
            f"*Top: the pressure mode; bottom: the paddle mode. This page is the docstring of "
            f"`{InflatedBallEnv.__module__}.{InflatedBallEnv.__name__}` (`{ENV_SOURCE}`).*",
            "",
            "| id | keyword arguments | observation (fast preset) | time limit (steps) |",
            "|---|---|---|---:|",
            *rows,
            "",
            '`import ballenv` registers the ids; `gymnasium.make("ballenv:InflatedBall-v3")` imports it.',
            "",
            inspect.getdoc(InflatedBallEnv),
            "",
        ]
    )
