"""The user manual: generated references and the build's failure modes.

- The configuration reference is generated from the pydantic schema and the CLI
  reference from the parser: a key or an option added there appears in the reference
  with no hand edit (shown by adding one).
- ``mkdocs build --strict`` with the repository's ``mkdocs.yml`` fails on a code block
  that raises and on a link to a page that does not exist (shown on small sites built
  with the same configuration), and passes on a correct one.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from pydantic import BaseModel, Field, create_model

from heritage_bayes.cli import _build_parser
from heritage_bayes.config import CalibrationConfig
from heritage_bayes.reference import cli_reference, parser_reference, schema_reference
from test_report import TINY as REPORT_TINY

ROOT = Path(__file__).resolve().parents[1]


# --------------------------------------------------------------- configuration reference
def _all_key_paths(model: type[BaseModel], prefix: str = "") -> set[str]:
    """Every key path of the schema, independently of the generator's walk (the keys of a
    list or a mapping of sections read like those of one section, as error messages
    name them)."""
    import typing

    keys = set()
    for name, field in model.model_fields.items():
        if name == "base_dir":  # set by the loader, not a key of the file
            continue
        path = f"{prefix}.{name}" if prefix else name
        keys.add(path)
        todo = [(field.annotation, path)]
        while todo:
            tp, p = todo.pop()
            args = typing.get_args(tp)
            if isinstance(tp, type) and issubclass(tp, BaseModel):
                keys |= _all_key_paths(tp, p)
            else:
                todo += [(a, p) for a in args]
    return keys


def test_config_reference_lists_every_key_of_the_schema():
    text = schema_reference(CalibrationConfig)
    missing = [k for k in _all_key_paths(CalibrationConfig) if f"`{k}`" not in text]
    assert missing == []
    assert "`periods.calibration.start`" in text


def test_a_key_added_to_the_schema_appears_in_the_reference():
    extra = create_model(
        "Extra",
        __base__=CalibrationConfig,
        wall_thickness=(
            float,
            Field(
                default=0.5,
                gt=0,
                le=5,
                description="thickness of the outer wall",
                json_schema_extra={"unit": "m"},
                examples=[0.9],
            ),
        ),
    )
    before = schema_reference(CalibrationConfig)
    after = schema_reference(extra)
    assert "wall_thickness" not in before
    row = next(line for line in after.splitlines() if line.startswith("| `wall_thickness`"))
    assert row == (
        "| `wall_thickness` | float | `0.5` | > 0, ≤ 5 | [m] thickness of the outer wall "
        "Example: `0.9` |"
    )


def test_sections_get_one_linked_table_each():
    class Inner(BaseModel):
        """A nested block."""

        tau: float = Field(description="a time constant", json_schema_extra={"unit": "h"})

    class Root(BaseModel):
        one: Inner | None = None
        named: dict[str, int] = Field(default_factory=dict, description="a | b")

    text = schema_reference(Root, title="Root file")
    assert "## `one` { #root-one }\n\nA nested block." in text
    assert "| `one` | [section](#root-one) | see section |" in text
    assert "| `one.tau` | float | **required** |  | [h] a time constant |" in text
    assert "a \\| b" in text  # a pipe in a description does not split the table row


# --------------------------------------------------------------------- CLI reference
def _commands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def test_cli_reference_lists_every_command_and_option():
    parser = _build_parser()
    text = cli_reference()
    for name, sub in _commands(parser).items():
        assert f"`hbayes {name}`" in text
        for action in sub._actions:
            for opt in action.option_strings:
                assert f"`{opt}`" in text, (name, opt)


def test_an_option_added_to_the_parser_appears_in_the_reference():
    parser = _build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    new = sub.add_parser("inspect", help="look at a logger file", description="Look at it.")
    new.add_argument("file", help="the logger export")
    new.add_argument("--step", metavar="DURATION", default="1h", help="grid step")
    new.add_argument("--fmt", choices=["hobo", "meaco"], help="file layout")
    assert "hbayes inspect" not in cli_reference()
    text = parser_reference(parser)
    assert "### `hbayes inspect`\n\nLook at it." in text
    assert "| `FILE` | required | the logger export |" in text
    assert "| `--step` | `DURATION` | grid step (default `1h`) |" in text
    assert "| `--fmt` | `FMT` | file layout (one of `hobo`, `meaco`) |" in text


# ------------------------------------------------------------- config examples
def test_config_examples_of_the_manual_are_checked_like_a_config():
    from heritage_bayes.errors import ConfigError
    from heritage_bayes.reference import check_config_snippet, check_projection_snippet

    ok = "thermal:\n  model: thermal_2c\n  options: {thermostat: true}\n"
    assert check_config_snippet(ok) == f"```yaml\n{ok.strip()}\n```"
    with pytest.raises(ConfigError, match=r"thermal\.modle"):
        check_config_snippet("thermal: {modle: thermal_2c}")
    with pytest.raises(ConfigError, match="thermostat"):  # a model option, not the schema
        check_config_snippet("hygric: {model: hygric_2c, options: {thermostat: true}}")
    with pytest.raises(ConfigError, match=r"sampler\.max_time"):
        check_config_snippet("sampler: {max_time: 10}")
    with pytest.raises(ConfigError, match="draws"):
        check_projection_snippet("draws: -1\nmorphing: []\n")


# --------------------------------------------------------------------- the build
def _mkdocs_site(tmp_path: Path, pages: dict[str, str]) -> Path:
    """A small site built with the repository's mkdocs.yml (only docs and nav replaced)."""
    cfg = yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))
    docs = tmp_path / "docs"
    docs.mkdir()
    for name, text in pages.items():
        (docs / name).write_text(text, encoding="utf-8")
    cfg.update(docs_dir=str(docs), site_dir=str(tmp_path / "site"), nav=list(pages))
    cfg.pop("extra_javascript", None)
    for plugin in cfg["plugins"]:
        if isinstance(plugin, dict) and "mkdocstrings" in plugin:
            plugin["mkdocstrings"]["handlers"]["python"]["paths"] = [str(ROOT / "src")]
    path = tmp_path / "mkdocs.yml"
    path.write_text(yaml.safe_dump(cfg), encoding="utf-8")
    return path


def _build(config: Path) -> subprocess.CompletedProcess:
    # not with -q: mkdocs counts warnings only when it logs them, and -q hides them
    return subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "-f", str(config)],
        capture_output=True,
        text=True,
        env={**os.environ, "NO_MKDOCS_2_WARNING": "1"},
    )


GOOD = """# Good

```python exec="on"
print(f"two and two make {2 + 2}")
```

See [the other page](other.md).
"""


@pytest.fixture(scope="module")
def _mkdocs():
    pytest.importorskip("mkdocs")
    pytest.importorskip("markdown_exec")
    pytest.importorskip("mkdocstrings")


def test_a_correct_page_builds_and_its_code_runs(tmp_path, _mkdocs):
    cfg = _mkdocs_site(tmp_path, {"index.md": GOOD, "other.md": "# Other\n"})
    res = _build(cfg)
    assert res.returncode == 0, res.stderr
    html = (tmp_path / "site" / "index.html").read_text(encoding="utf-8")
    assert "two and two make 4" in html


def test_a_broken_code_block_fails_the_build(tmp_path, _mkdocs):
    broken = GOOD.replace("{2 + 2}", "{2 + undefined_name}")
    cfg = _mkdocs_site(tmp_path, {"index.md": broken, "other.md": "# Other\n"})
    res = _build(cfg)
    assert res.returncode != 0
    assert "undefined_name" in res.stderr


def test_a_dangling_cross_reference_fails_the_build(tmp_path, _mkdocs):
    cfg = _mkdocs_site(tmp_path, {"index.md": GOOD.replace("other.md", "gone.md"),
                                  "other.md": "# Other\n"})  # fmt: skip
    res = _build(cfg)
    assert res.returncode != 0
    assert "gone.md" in res.stderr


def test_a_dangling_api_reference_fails_the_build(tmp_path, _mkdocs):
    page = "# API\n\n::: heritage_bayes.run.no_such_function\n"
    cfg = _mkdocs_site(tmp_path, {"index.md": page})
    res = _build(cfg)
    assert res.returncode != 0
    assert "no_such_function" in res.stderr


# ------------------------------------------------------- the report's "From Python"
# the report tests' tiny run (10 + 5 days of the demo, 600 steps), without the ladder
TINY = {**REPORT_TINY, "ladder": False}


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory) -> Path:
    from heritage_bayes.calibration.calibrate import run_calibration
    from heritage_bayes.config import parse_config

    run_dir = tmp_path_factory.mktemp("docs") / "a run's folder"  # a quote, a space
    run_calibration(parse_config(TINY), out_dir=run_dir, report=False, quiet=True)
    return run_dir


def test_the_reports_from_python_lines_run_as_printed(tiny_run):
    """The report prints Python that opens its own run; it runs in a fresh interpreter
    exactly as the page shows it (HTML entities undone, nothing else)."""
    import html
    import re

    from heritage_bayes.report import write_report

    page = write_report(tiny_run).read_text(encoding="utf-8")
    m = re.search(r'<pre class="config" id="from-python">(.*?)</pre>', page, re.S)
    assert m, "the report has no From Python block"
    code = html.unescape(m.group(1))
    assert repr(str(tiny_run.resolve())) in code  # the path is a Python literal
    res = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=tiny_run.parent
    )
    assert res.returncode == 0, res.stderr
    assert res.stdout.startswith("converged: False")  # 600 steps: not converged
    for name in ("thermal.tau_1_h", "thermal.gain_Ti_Te", "hygric.tau_1_h"):
        assert name in res.stdout
    assert re.search(r"^thermal \{'Ci': [0-9.e+]+, ", res.stdout, re.M)


def test_the_from_python_lines_name_the_run_not_its_staging_folder(tiny_run, tmp_path):
    """calibrate writes the report inside the staging folder ``.<name>.partial`` and
    then swaps it in as ``<name>``: the lines must open ``<name>``, which exists after
    the run, never the staging folder, which does not."""
    import html
    import re
    import shutil

    from heritage_bayes.report import write_report
    from heritage_bayes.rundir.writer import published_path, staging_path

    final = tmp_path / "room"
    staged = staging_path(final)
    assert published_path(staged) == final and published_path(final) == final
    shutil.copytree(tiny_run, staged)
    page = write_report(staged).read_text(encoding="utf-8")
    code = html.unescape(re.search(r'id="from-python">(.*?)</pre>', page, re.S).group(1))
    assert repr(str(final.resolve())) in code
    assert ".partial" not in page


def test_the_readmes_python_block_runs(tiny_run):
    """The README's "From Python" block, on a run in place of ``reports/demo``."""
    import re

    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", readme, re.S)
    assert len(blocks) == 1
    assert '"reports/demo"' in blocks[0]
    code = blocks[0].replace('"reports/demo"', repr(str(tiny_run)))
    code += "\nprint(sorted(draws), run.summary['converged'])\n"
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == "['Ci', 'Ge', 'Gf', 'fI_E', 'fI_N', 'fI_S', 'fI_W'] False"


def test_ci_runs_the_readmes_test_command():
    """``.ci/run`` prints and runs the README's second command, character for character."""
    import re

    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    block = re.search(r"```bash\n(.*?)```", readme, re.S).group(1)
    commands = [line for line in block.splitlines() if line and not line.startswith("#")]
    assert len(commands) == 2 and "pytest" in commands[1], commands
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert f"TEST_COMMAND='{commands[1]}'\n" in ci
    assert 'echo "$TEST_COMMAND"\neval "$TEST_COMMAND"\n' in ci
