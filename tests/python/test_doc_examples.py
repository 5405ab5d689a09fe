"""The examples of the README and of every page of docs/ are tests (docs/guide/install.md says
how the site shows them):

- every ```pycon session runs as a doctest;
- every code block marked `<!-- file: PATH -->` is that file verbatim, and every block marked
  `<!-- excerpt: PATH -->` a verbatim part of it; the files themselves are built and run by
  ctest (the example_* tests: examples/CMakeLists.txt; examples/pytest-driver is
  example_pytest_driver) and by tests/install/install_test.sh against an installed package;
- every ```sh block marked `<!-- run -->` (or `<!-- run: exit N -->`) runs with bash, from a
  folder where build/ is this build tree and examples/, fixtures/, scripts/ and docs/ are the
  source tree's, and must exit 0 (or N).

The guides must show the examples a newcomer copies: GoogleTest, the STM32 HAL program, the
pytest driver test and `run`, each as a file that is built and run."""
import doctest
import os
import re
import subprocess
from pathlib import Path

import pytest

import l6470emu

SOURCE_DIR = Path(__file__).resolve().parents[2]
PAGES = sorted({SOURCE_DIR / "README.md", *SOURCE_DIR.glob("docs/**/*.md"), *SOURCE_DIR.glob("examples/**/README.md")})
FENCE = r"```[a-z]*\n(.*?)```"
# The examples each guide must show as a file (and so as something a test builds and runs).
SHOWN = {
    "docs/guide/cpp.md": ["examples/googletest/chain_test.cpp", "examples/googletest/CMakeLists.txt"],
    "docs/guide/firmware.md": ["examples/stm32-hal/main.c", "examples/stm32-hal/CMakeLists.txt",
                               "examples/arduino-sketch/arduino-sketch.ino", "examples/arduino-sketch/CMakeLists.txt"],
    "docs/guide/python.md": ["examples/pytest-driver/test_stepper_driver.py"],
    "docs/guide/ci.md": ["examples/run/homing.yaml", "examples/run/homing.board"],
    "docs/guide/install.md": ["examples/cmake-consumer/CMakeLists.txt", "examples/cmake-consumer/main.cpp"],
}


def page_id(page):
    return str(page.relative_to(SOURCE_DIR))


def marked(text, marker):
    """(argument, block) of every fenced block right after `<!-- marker: argument -->`."""
    return re.findall(r"<!-- " + marker + r"(?:: ([^>]*?))? -->\n" + FENCE, text, re.S)


@pytest.mark.parametrize("page", PAGES, ids=page_id)
def test_every_python_session_runs_as_shown(page):
    sessions = re.findall(r"```pycon\n(.*?)```", page.read_text(), re.S)
    parser = doctest.DocTestParser()
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    for i, text in enumerate(sessions):
        runner.run(parser.get_doctest(text, {}, f"{page_id(page)} pycon block {i + 1}", str(page), 0))
    assert runner.summarize(verbose=False).failed == 0


def test_the_readme_and_the_python_guide_have_sessions():
    for page in ("README.md", "docs/guide/python.md"):
        assert "```pycon" in (SOURCE_DIR / page).read_text(), page


@pytest.mark.parametrize("page", PAGES, ids=page_id)
def test_every_file_shown_is_the_file_itself(page):
    for path, text in marked(page.read_text(), "file"):
        assert (SOURCE_DIR / path).read_text() == text, f"{page_id(page)}'s copy of {path} differs from the file"
    for path, text in marked(page.read_text(), "excerpt"):
        assert text in (SOURCE_DIR / path).read_text(), f"{page_id(page)}'s excerpt of {path} is not in the file"


@pytest.mark.parametrize("page", sorted(SHOWN), ids=str)
def test_each_guide_shows_its_examples_as_files(page):
    shown = {path for path, _ in marked((SOURCE_DIR / page).read_text(), "file")}
    missing = [path for path in SHOWN[page] if path not in shown]
    assert not missing, f"{page} does not show {missing} as <!-- file: --> blocks"


RUN_BLOCKS = [(page, i, status, block) for page in PAGES
              for i, (status, block) in enumerate(marked(page.read_text(), "run"))]


def test_the_guides_have_blocks_that_run():
    pages = {page_id(page) for page, *_ in RUN_BLOCKS}
    assert {"README.md", "docs/guide/ci.md"} <= pages, pages


@pytest.mark.parametrize("page,index,status,block", RUN_BLOCKS,
                         ids=[f"{page_id(p)}-run{i + 1}" for p, i, _, _ in RUN_BLOCKS])
def test_every_block_marked_to_run_runs(page, index, status, block, tmp_path):
    build = Path(l6470emu.program()).parent  # the build tree whose module this is
    if not (build / "CMakeCache.txt").exists():
        pytest.skip(f"not a build tree's module ({build}): the blocks name build/")
    for name, target in (("build", build), ("examples", SOURCE_DIR / "examples"), ("fixtures", SOURCE_DIR / "fixtures"),
                         ("scripts", SOURCE_DIR / "scripts"), ("docs", SOURCE_DIR / "docs")):
        (tmp_path / name).symlink_to(target)
    expected = int(status.split()[-1]) if status else 0
    env = {k: v for k, v in os.environ.items() if not k.startswith("L6470EMU_")}
    result = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", block], cwd=tmp_path, env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=300)
    assert result.returncode == expected, (
        f"{page_id(page)}, block {index + 1} exited {result.returncode}, not {expected}:\n{block}\n{result.stdout[-4000:]}")
