"""The README's examples are tests: its Python session runs as a doctest, and every code block
marked `<!-- file: PATH -->` in it and in docs/firmware.md is that file verbatim (the files
themselves are built and run by tests/install/install_test.sh and by ctest's examples:
examples/pytest-driver is ctest's example_pytest_driver)."""
import doctest
import re
from pathlib import Path

SOURCE_DIR = Path(__file__).resolve().parents[2]

README = (SOURCE_DIR / "README.md").read_text()


def test_the_python_session_in_the_readme_runs_as_shown():
    sessions = re.findall(r"```pycon\n(.*?)```", README, re.S)
    assert sessions, "the README has no ```pycon block"
    parser = doctest.DocTestParser()
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    for i, text in enumerate(sessions):
        test = parser.get_doctest(text, {}, f"README.md pycon block {i + 1}", "README.md", 0)
        runner.run(test)
    assert runner.summarize(verbose=False).failed == 0


def test_every_file_shown_in_the_readme_is_the_file_itself():
    blocks = re.findall(r"<!-- file: (\S+) -->\n```[a-z]*\n(.*?)```", README, re.S)
    assert len(blocks) >= 3, "the README shows the CMake consumer and the pytest example"
    for path, text in blocks:
        assert (SOURCE_DIR / path).read_text() == text, f"README.md's copy of {path} differs from the file"


def test_every_file_shown_in_the_firmware_page_is_the_file_itself():
    page = (SOURCE_DIR / "docs" / "firmware.md").read_text()
    blocks = re.findall(r"<!-- file: (\S+) -->\n```[a-z]*\n(.*?)```", page, re.S)
    assert blocks, "docs/firmware.md shows the C-API shim"
    for path, text in blocks:
        assert (SOURCE_DIR / path).read_text() == text, f"docs/firmware.md's copy of {path} differs from the file"
