#!/usr/bin/python3
"""Builds the documentation site into the build tree (the `l6470emu_docs` target and ctest's
`docs` test run this). Nothing is written into the source tree.

1. Stages the source tree into BUILD/docs/site-src: every Markdown page (README.md, docs/, the
   examples' READMEs ...) copied, everything else linked, so that a page's links to source files
   resolve as they do on GitHub.
2. Generates what must not drift: the tables of `l6470emu tables` refreshed in the staged pages,
   a page per subcommand from `l6470emu SUB --help`, the C++ API pages from the list of public
   headers, and Doxygen's XML of those headers.
3. Runs Sphinx (MyST, autodoc over the built module, Breathe) with warnings as errors.
4. Checks the built HTML: every relative link and anchor resolves, every public name of the
   Python module and every public header has its entry.

Usage: build_site.py --source SRC --build BUILD [--jobs N]
Exit status 0 built, 1 a warning or a broken link, 77 a package the build needs is missing
(said on one line)."""
import argparse
import filecmp
import html.parser
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path
from urllib.parse import unquote, urlsplit

SKIP = 77
# The public headers of the C++ API (installed ones: cmake/install_headers.cmake) and the C API.
CPP_LAYERS = {
    "core": "the chip: variant tables, register file, command decoder, STATUS, pins, motion, axis",
    "spi": "bus framing, the bit-level interface, trace formats",
    "daisychain": "N chips behind one chip-select; ChainHost, decode, replay, recording",
    "board": "the OS-free board: chains on buses, pins, one clock, recorder, sanitizer, scenarios, coverage",
}
PRIVATE_HEADER = re.compile(r"(_internal\.hpp|import_support\.hpp)$")
C_API_HEADERS = ["firmware/firmware.h"]
FRAMEWORK_JS = ("jquery.js", "underscore.js", "_sphinx_javascript_frameworks_compat.js")


def say(*args):
    print("build_site:", *args, flush=True)


def missing_packages():
    """What the build needs that is not installed, as Debian package names."""
    missing = []
    for module, package in (("sphinx", "python3-sphinx"), ("myst_parser", "python3-myst-parser"),
                            ("breathe", "python3-breathe")):
        try:
            __import__(module)
        except ImportError:
            missing.append(package)
    if not shutil.which("doxygen"):
        missing.append("doxygen")
    return missing


# ---- 1. staging -------------------------------------------------------------------------------

def is_page(rel):
    return rel.suffix == ".md"


def stage(source, stage_dir):
    """Mirrors the source tree: pages copied (only when changed, so Sphinx rebuilds only what
    changed), other files and folders without pages linked. Build trees and hidden folders are
    left out. Returns the set of staged paths (relative)."""
    kept = set()

    def has_page(directory):
        for root, dirs, files in os.walk(directory):
            dirs[:] = [d for d in dirs if not d.startswith(".") and d != "__pycache__"]
            if any(f.endswith(".md") for f in files):
                return True
        return False

    def mirror(rel):
        src_dir = source / rel
        for entry in sorted(os.listdir(src_dir)):
            if entry.startswith(".") or entry == "__pycache__" or (rel == Path(".") and entry.startswith("build")):
                continue
            r = rel / entry
            s, d = source / r, stage_dir / r
            if s.is_dir() and not s.is_symlink() and has_page(s):
                if d.is_symlink() or (d.exists() and not d.is_dir()):
                    d.unlink()
                d.mkdir(parents=True, exist_ok=True)
                kept.add(r)
                mirror(r)
            elif is_page(r) and s.is_file():
                if d.is_symlink():
                    d.unlink()
                if not d.exists() or not filecmp.cmp(s, d, shallow=False):
                    shutil.copyfile(s, d)
                kept.add(r)
            else:
                if d.is_symlink() and os.readlink(d) == str(s):
                    pass
                else:
                    if d.is_dir() and not d.is_symlink():
                        shutil.rmtree(d)
                    elif d.exists() or d.is_symlink():
                        d.unlink()
                    d.symlink_to(s)
                kept.add(r)

    stage_dir.mkdir(parents=True, exist_ok=True)
    mirror(Path("."))
    return {Path(os.path.normpath(p)) for p in kept}


def write_if_changed(path, text):
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.exists() and path.read_text() == text:
        return
    path.write_text(text)


def remove_stale(stage_dir, kept):
    """Removes staged files that neither the source nor this build made."""
    for root, dirs, files in os.walk(stage_dir, topdown=False):
        root_path = Path(root)
        for name in files + dirs:
            p = root_path / name
            rel = p.relative_to(stage_dir)
            if p.is_symlink() or p.is_file():
                if rel not in kept:
                    p.unlink()
            elif p.is_dir() and rel not in kept and not any(p.iterdir()):
                p.rmdir()


# ---- 2. generated pages -----------------------------------------------------------------------

def run(argv, **kwargs):
    return subprocess.run(argv, check=True, text=True, stdout=subprocess.PIPE, **kwargs).stdout


def refresh_tables(program, stage_dir, pages):
    """`l6470emu tables --update-readme` on every staged page with a generated block: the site
    shows the tables of the program it documents, whatever the checked-in copy says."""
    for rel in sorted(pages):
        path = stage_dir / rel
        if path.suffix == ".md" and not path.is_symlink() and "<!-- BEGIN generated:" in path.read_text():
            run([program, "tables", "--update-readme", str(path)])


def subcommands(help_text):
    """The subcommand names of a CLI11 help text (its Subcommands: section)."""
    names = []
    section = re.split(r"^Subcommands:$", help_text, maxsplit=1, flags=re.M | re.I)
    if len(section) == 2:
        for line in section[1].splitlines():
            m = re.match(r"^  (\S+)\s", line)
            if m:
                names.append(m.group(1))
            elif line.strip() and not line.startswith(" "):
                break
    return names


def cli_pages(program, out_dir):
    """A page per subcommand and per sub-subcommand with its --help (docs/reference/cli.md lists
    them), and one with the program's own. Returns the written paths and the page names."""
    written, names = [], []

    def page(words, title, about):
        text = run([program, *words, "--help"])
        name = "-".join(words) or "l6470emu"
        body = [f"# `{title}`", "", about, "", "```{code-block} text", ":class: cli-help", "", text.rstrip("\n"), "```", ""]
        nested = subcommands(text) if words else []
        if nested:
            body += ["Its subcommands: " + ", ".join(f"[`{title} {n}`]({name}-{n}.md)" for n in nested) + ".", ""]
        path = out_dir / f"{name}.md"
        write_if_changed(path, "\n".join(body))
        written.append(path)
        names.append(name)
        for n in nested:
            page(words + [n], f"{title} {n}", f"The output of `{title} {n} --help`, generated when this site was built.")

    top = run([program, "--help"])
    if not subcommands(top):
        raise SystemExit("build_site: `l6470emu --help` lists no subcommands")
    page([], "l6470emu", "The program's own help, generated when this site was built: its subcommands.")
    for n in subcommands(top):
        page([n], f"l6470emu {n}", f"The output of `l6470emu {n} --help`, generated when this site was built.")
    return written, names


def public_headers(source):
    headers = {}
    for layer in CPP_LAYERS:
        headers[layer] = sorted(str(p.relative_to(source)) for p in (source / layer).glob("*.hpp")
                                if not PRIVATE_HEADER.search(p.name))
    return headers


def first_comment(path):
    """A header's opening comment (what it models), as one paragraph."""
    lines = []
    for line in path.read_text().splitlines():
        if line.startswith("//"):
            lines.append(line.lstrip("/").strip())
        elif line.startswith(("/*", " *")):
            lines.append(line.strip().lstrip("/*").rstrip("*/").strip())
            if line.rstrip().endswith("*/"):
                break
        else:
            break
    return " ".join(l for l in lines if l)


def doxygen_entities(xml_dir):
    """What Doxygen found in namespace l6470emu (and the namespaces inside it), by the header that
    declares it: [(kind, qualified name, argsstring)], in the header's order."""
    import xml.etree.ElementTree as ET
    by_file = {}

    def add(location, line, entity):
        if location is not None:
            by_file.setdefault(location, []).append((line, entity))

    def namespace(refid):
        root = ET.parse(xml_dir / f"{refid}.xml").getroot().find("compounddef")
        ns = root.findtext("compoundname")
        for inner in root.findall("innerclass"):
            cls = ET.parse(xml_dir / f"{inner.get('refid')}.xml").getroot().find("compounddef")
            if cls.get("prot") not in (None, "public"):
                continue
            loc = cls.find("location")
            add(loc.get("file") if loc is not None else None, int(loc.get("line", 0)) if loc is not None else 0,
                (cls.get("kind"), inner.text, ""))
        for member in root.iter("memberdef"):
            loc = member.find("location")
            name = f"{ns}::{member.findtext('name')}"
            add(loc.get("file"), int(loc.get("line", 0)), (member.get("kind"), name, member.findtext("argsstring") or ""))
        for inner in root.findall("innernamespace"):
            namespace(inner.get("refid"))

    namespace("namespacel6470emu")
    return {f: [e for _, e in sorted(v, key=lambda x: x[0])] for f, v in by_file.items()}


def api_pages(source, xml_dir, out_dir, headers):
    """A page per layer, a section per public header, a Breathe directive per class, enum,
    type, variable and function the header declares (overloads told apart by their arguments)."""
    entities = doxygen_entities(xml_dir)
    directive = {"class": "doxygenclass", "struct": "doxygenstruct", "union": "doxygenunion", "enum": "doxygenenum",
                 "typedef": "doxygentypedef", "variable": "doxygenvariable", "function": "doxygenfunction"}
    names = [n for listed in entities.values() for _, n, _ in listed]
    written = []
    for layer, about in CPP_LAYERS.items():
        body = [f"# `{layer}/`", "", f"{about[0].upper()}{about[1:]}. Installed as `<l6470emu/{layer}/...>`, linked as "
                f"`l6470emu::{layer}`.", ""]
        for h in headers[layer]:
            body += [f"## `{h}`", "", first_comment(source / h).replace("*", "\\*"), ""]
            for kind, name, args in entities.get(h, []):
                if kind not in directive:
                    continue
                target = name + (args.split(")")[0] + ")" if kind == "function" and names.count(name) > 1 else "")
                body += ["```{" + directive[kind] + "} " + target, ":project: l6470emu"]
                if kind in ("class", "struct", "union"):
                    body += [":members:", ":undoc-members:"]
                body += ["```", ""]
        path = out_dir / f"{layer}.md"
        write_if_changed(path, "\n".join(body))
        written.append(path)
    return written


DOXYFILE = """\
PROJECT_NAME           = l6470emu
OUTPUT_DIRECTORY       = {out}
GENERATE_HTML          = NO
GENERATE_LATEX         = NO
GENERATE_XML           = YES
XML_PROGRAMLISTING     = NO
INPUT                  = {inputs}
FULL_PATH_NAMES        = YES
STRIP_FROM_PATH        = {source}
STRIP_FROM_INC_PATH    = {source}
EXTRACT_ALL            = YES
EXTRACT_PRIVATE        = NO
EXTRACT_STATIC         = YES
EXTRACT_LOCAL_CLASSES  = NO
EXTRACT_ANON_NSPACES   = NO
HIDE_UNDOC_CLASSES     = NO
JAVADOC_AUTOBRIEF      = YES
QT_AUTOBRIEF           = YES
MARKDOWN_SUPPORT       = YES
ENABLE_PREPROCESSING   = YES
MACRO_EXPANSION        = YES
PREDEFINED             = __cplusplus
EXCLUDE_SYMBOLS        = detail detail::* *::detail::*
QUIET                  = YES
MAX_INITIALIZER_LINES  = 1
WARNINGS               = NO
WARN_IF_UNDOCUMENTED   = NO
WARN_LOGFILE           = {out}/warnings.log
# Datasheet names written with a backslash or an at sign (BUSY\\SYNC, STBY\\RST, NAME@POS) stay text.
ALIASES                = "SYNC=\\\\SYNC" "RST=\\\\RST" "xNN=\\\\xNN" "DEV=\\@DEV" "POS=\\@POS"
"""


def doxygen(source, out, headers):
    inputs = [source / h for layer in headers.values() for h in layer] + [source / h for h in C_API_HEADERS]
    stamp = out / "stamp"
    doxyfile = DOXYFILE.format(out=out, inputs=" ".join(str(p) for p in inputs), source=source)
    config = out / "Doxyfile"
    newest = max(p.stat().st_mtime for p in inputs)
    if (stamp.exists() and config.exists() and config.read_text() == doxyfile
            and stamp.stat().st_mtime >= newest):
        return
    out.mkdir(parents=True, exist_ok=True)
    config.write_text(doxyfile)
    if (out / "xml").exists():
        shutil.rmtree(out / "xml")
    subprocess.run(["doxygen", str(config)], check=True, stdout=subprocess.DEVNULL)
    stamp.touch()


# ---- 4. checks over the HTML ------------------------------------------------------------------

class Links(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.links, self.ids = [], set()

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        for key in ("id", "name"):
            if a.get(key):
                self.ids.add(a[key])
        for key in ("href", "src"):
            if a.get(key) is not None and not (tag == "link" and a.get("rel") in ("canonical",)):
                self.links.append((key, a[key]))


def check_links(out_dir):
    """Every relative href and src of every page resolves to a built file, and every #anchor to
    an id of it. Returns the broken ones."""
    parsed = {}

    def parse(path):
        if path not in parsed:
            p = Links()
            p.feed(path.read_text(errors="replace"))
            parsed[path] = p
        return parsed[path]

    broken = []
    pages = sorted(out_dir.rglob("*.html"))
    for page in pages:
        for key, link in parse(page).links:
            parts = urlsplit(link)
            if parts.scheme or link.startswith("//"):
                continue  # external: not followed (no network), and not ours
            if not parts.path:
                target = page
            else:
                target = (page.parent / unquote(parts.path)).resolve()
            if not target.exists():
                broken.append(f"{page.relative_to(out_dir)}: {key}={link}: no such file")
                continue
            if target.is_dir():
                target = target / "index.html"
                if not target.exists():
                    broken.append(f"{page.relative_to(out_dir)}: {key}={link}: a folder")
                    continue
            if parts.fragment and target.suffix == ".html":
                if unquote(parts.fragment) not in parse(target).ids:
                    broken.append(f"{page.relative_to(out_dir)}: {key}={link}: no anchor #{parts.fragment}")
    return broken, len(pages)


def check_completeness(out_dir, python_path, headers, cli_names):
    problems = []
    api = (out_dir / "docs/reference/python-api.html")
    ids = Links()
    ids.feed(api.read_text())
    names = run([sys.executable, "-c", "import l6470emu; print('\\n'.join(l6470emu.__all__))"],
                env={**os.environ, "PYTHONPATH": python_path}).split()
    for name in names:
        if f"l6470emu.{name}" not in ids.ids and f"module-l6470emu.{name}" not in ids.ids:
            problems.append(f"the Python API page has no entry for l6470emu.{name}")
    for layer, hs in headers.items():
        text = (out_dir / f"docs/reference/cpp/{layer}.html").read_text()
        for h in hs:
            if h not in text:
                problems.append(f"the C++ API page of {layer}/ lacks {h}")
    for name in cli_names:
        if not (out_dir / f"docs/reference/cli/{name}.html").exists():
            problems.append(f"no page for `l6470emu {name}`")
    return problems


# ---- main -------------------------------------------------------------------------------------

def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--source", required=True, type=Path)
    ap.add_argument("--build", required=True, type=Path)
    ap.add_argument("--program", type=Path, help="the l6470emu program (default BUILD/l6470emu)")
    ap.add_argument("--python-path", help="where the built module is (default BUILD/python)")
    ap.add_argument("--jobs", default="1", help="Sphinx's -j")
    args = ap.parse_args()
    source, build = args.source.resolve(), args.build.resolve()
    program = str(args.program or build / "l6470emu")
    python_path = args.python_path or str(build / "python")

    missing = missing_packages()
    if missing:
        print(f"build_site: SKIPPED: the documentation site needs {', '.join(missing)} "
              f"(apt-get install {' '.join(missing)}; scripts/setup.sh installs them)", flush=True)
        return SKIP
    for what, path in (("the l6470emu program", Path(program)), ("the Python module", Path(python_path) / "l6470emu")):
        if not path.exists():
            say(f"{what} is not built ({path}): build the l6470emu and l6470emu_python targets first")
            return 1

    started = time.monotonic()
    work = build / "docs"
    stage_dir, out_dir = work / "site-src", work / "html"
    kept = stage(source, stage_dir)
    pages = {p for p in kept if is_page(p)}
    refresh_tables(program, stage_dir, pages)
    cli_written, cli_names = cli_pages(program, stage_dir / "docs/reference/cli")
    headers = public_headers(source)
    doxygen(source, work / "doxygen", headers)
    api_written = api_pages(source, work / "doxygen/xml", stage_dir / "docs/reference/cpp", headers)
    for p in cli_written + api_written:
        rel = p.relative_to(stage_dir)
        kept.add(rel)
        kept.update(rel.parents)
    remove_stale(stage_dir, kept)
    say(f"staged and generated in {time.monotonic() - started:.1f} s")

    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [python_path, os.environ.get("PYTHONPATH")])),
           "L6470EMU_DOXYGEN_XML": str(work / "doxygen/xml"), "L6470EMU_SITE_SRC": str(stage_dir),
           "PYTHONDONTWRITEBYTECODE": "1"}
    sphinx = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", "-j", str(args.jobs),
              "-c", str(source / "docs"), "-d", str(work / "doctrees"), str(stage_dir), str(out_dir)]
    t = time.monotonic()
    if subprocess.run(sphinx, env=env).returncode != 0:
        say("Sphinx reported warnings (above): the site is not built")
        return 1
    say(f"Sphinx built the site in {time.monotonic() - t:.1f} s")

    for name in FRAMEWORK_JS:
        for f in out_dir.glob(f"_static/{name}"):
            f.unlink()
    # Sphinx leaves the page of a removed or renamed document behind: remove it, so that neither
    # the checks below nor an install see it.
    built = {str(p.with_suffix(".html")) for p in kept if is_page(p) and (stage_dir / p).is_file()
             and not (stage_dir / p).is_symlink()}
    built |= {"index.html", "search.html", "genindex.html", "py-modindex.html"}
    for page in out_dir.rglob("*.html"):
        rel = page.relative_to(out_dir)
        if rel.parts[0] not in ("_static", "_downloads", "_images") and str(rel) not in built:
            say(f"removed {rel}: no page makes it any more")
            page.unlink()
    # The front page is docs/index.html (the pages keep the source tree's layout, so that their
    # links to each other and to source files are the ones GitHub shows).
    write_if_changed(out_dir / "index.html",
                     '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
                     '<meta http-equiv="refresh" content="0; url=docs/index.html">'
                     '<title>l6470emu</title></head>\n<body><p><a href="docs/index.html">l6470emu documentation</a></p>'
                     '</body></html>\n')

    broken, count = check_links(out_dir)
    problems = broken + check_completeness(out_dir, python_path, headers, cli_names)
    for p in problems:
        say(p)
    if problems:
        say(f"{len(problems)} problems in the built site ({out_dir})")
        return 1
    say(f"{count} pages, every internal link and anchor resolves; built in {time.monotonic() - started:.1f} s: "
        f"{out_dir / 'index.html'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
