# Sphinx configuration of the documentation site (docs/build_site.py stages docs/ into the
# build tree and runs sphinx-build there; never run on the source tree itself). The pages are
# the Markdown files of docs/ (MyST), the Python API by autodoc from the built module, the C and
# C++ APIs by Breathe from Doxygen's XML of the public headers, and pages generated at build
# time (every subcommand's --help, the C++ header list) that exist only in the staged copy.
import os
from pathlib import Path

from docutils import nodes

project = "l6470emu"
author = "l6470emu maintainers"
copyright = "l6470emu maintainers"
version = release = os.environ.get("L6470EMU_DOCS_VERSION", "")

extensions = ["myst_parser", "sphinx.ext.autodoc", "breathe"]
source_suffix = {".md": "markdown"}
root_doc = "docs/index"  # the site keeps the source tree's layout (build_site.py stages it)
exclude_patterns = []
language = "en"

# Links: every [text](target) without a scheme is an internal reference that must resolve (a
# page, a heading anchor, a file; a warning, and so an error, otherwise).
myst_all_links_external = False
myst_heading_anchors = 4  # GitHub's anchors (#the-board-description) for headings down to ####
suppress_warnings = []

default_role = "literal"  # `name` in a docstring is code, as the docstrings mean it

# Python: the built module (PYTHONPATH=BUILD/python, set by build_site.py).
autodoc_member_order = "bysource"
autodoc_typehints = "signature"
autodoc_default_options = {"members": True, "undoc-members": True, "show-inheritance": True}

# C and C++: Doxygen's XML of the public headers (build_site.py runs doxygen).
breathe_projects = {"l6470emu": os.environ.get("L6470EMU_DOXYGEN_XML", "doxygen/xml")}
breathe_default_project = "l6470emu"
breathe_domain_by_extension = {"h": "c", "hpp": "cpp"}
breathe_default_members = ("members",)
cpp_index_common_prefix = ["l6470emu::"]

html_theme = "alabaster"
html_title = "l6470emu"
html_theme_options = {
    "description": "register-level emulator of the ST L6470-family SPI motion engines",
    "fixed_sidebar": True,
    "page_width": "1180px",
    "sidebar_width": "250px",
}
html_sidebars = {"**": ["about.html", "navigation.html", "relations.html", "searchbox.html"]}
html_static_path = ["_static"]
html_js_files = ["file-protocol.js"]
html_css_files = ["site.css"]
html_copy_source = False  # no _sources/ copies of the pages
html_show_sourcelink = False



def _pages(stage_dir):
    """The pages: the Markdown files build_site.py copied into the staged tree (not those behind
    its links to the source tree's other folders)."""
    pages = []
    for root, dirs, files in os.walk(stage_dir):  # links to folders are not followed
        pages += [os.path.relpath(os.path.join(root, f), stage_dir) for f in files
                  if f.endswith(".md") and not os.path.islink(os.path.join(root, f))]
    return sorted(pages)


if os.environ.get("L6470EMU_SITE_SRC"):
    include_patterns = _pages(os.environ["L6470EMU_SITE_SRC"])


def _directory_links(app, env, node, contnode):
    """A link to a folder of the repository (`../examples/run/`) is no page and no file: it is
    shown as its text once the folder is known to exist; a missing one stays a warning."""
    target = node.get("reftarget", "")
    if node.get("reftype") not in ("myst", "any") or "://" in target or target.startswith("#"):
        return None
    doc_dir = Path(env.doc2path(node.get("refdoc", env.docname))).parent
    if (doc_dir / target).is_dir():
        return nodes.literal(target, contnode.astext())
    return None


def _drop_javascript_frameworks(app):
    """Sphinx 5 adds jQuery and underscore.js for old themes only; nothing of this site uses
    them, and a Debian package must not carry its own copies (lintian)."""
    builder = app.builder
    if hasattr(builder, "script_files"):
        builder.script_files[:] = [
            s for s in builder.script_files
            if os.path.basename(str(getattr(s, "filename", s))) not in
            ("jquery.js", "underscore.js", "_sphinx_javascript_frameworks_compat.js")
        ]


def _plain_text_docstrings(app, what, name, obj, options, lines):
    """The module's docstrings are plain text written for help() (indented continuation lines,
    `names` in backquotes), not reStructuredText. One that reStructuredText would misread is
    shown as it is written, as a literal block; the others as paragraphs."""
    import io

    import docutils.core
    import docutils.utils

    text = "\n".join(lines)
    if not text.strip():
        return
    stream = io.StringIO()
    try:
        docutils.core.publish_doctree(text, settings_overrides={
            "report_level": docutils.utils.Reporter.WARNING_LEVEL, "halt_level": 5,
            "warning_stream": stream, "file_insertion_enabled": False, "raw_enabled": False})
    except Exception:  # noqa: BLE001 - anything docutils cannot read is shown as written
        stream.write("unreadable")
    if stream.getvalue():
        lines[:] = ["::", ""] + ["   " + line for line in lines] + [""]


def setup(app):
    app.connect("autodoc-process-docstring", _plain_text_docstrings)
    app.connect("missing-reference", _directory_links)
    app.connect("builder-inited", _drop_javascript_frameworks)
