#!/usr/bin/python3
"""ctest `docs` (label docs): builds the documentation site into the build tree with
docs/build_site.py (warnings as errors, every internal link and anchor checked), then opens it
in headless Chromium (Debian's chromium, chromium-driver, python3-selenium) and checks what a
reader does first: the front page, a search for a register name, a Python class and a C++
class with their members, and no JavaScript error in the console of any of them.

Usage: docs_test.py --source SRC --build BUILD [--jobs N]
Exit status 0 passed, 1 failed, 77 skipped (a package is missing: said on one line; without
Sphinx nothing is built, without Chromium or Selenium the site is built and checked but not
opened)."""
import argparse
import shutil
import subprocess
import sys
import time
from pathlib import Path

SKIP = 77


def fail(message):
    print(f"docs_test: FAIL: {message}", flush=True)
    sys.exit(1)


def step(message):
    print(f"-- {message}", flush=True)


def browser():
    """A headless Chromium with its console log kept, or a reason why there is none."""
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
    except ImportError:
        return None, "python3-selenium is not installed"
    chromium = shutil.which("chromium")
    driver = shutil.which("chromedriver")
    if not chromium:
        return None, "chromium is not installed"
    if not driver:
        return None, "chromium-driver (chromedriver) is not installed"
    options = webdriver.ChromeOptions()
    options.binary_location = chromium
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                "--no-first-run", "--disable-extensions", "--disable-background-networking"):
        options.add_argument(arg)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    return webdriver.Chrome(service=Service(driver), options=options), None


def console_errors(driver):
    """The console's errors, but the browser's own request for /favicon.ico (the site has none)."""
    return [e["message"] for e in driver.get_log("browser")
            if e.get("level") == "SEVERE" and "/favicon.ico " not in e["message"]]


def serve(directory):
    """Serves `directory` on a free port of 127.0.0.1 for the rest of the test; its base URL."""
    import functools
    import http.server
    import threading

    class Quiet(http.server.SimpleHTTPRequestHandler):
        def log_message(self, *args):
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(Quiet, directory=str(directory)))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return f"http://127.0.0.1:{server.server_address[1]}"


def wait_for(predicate, what, timeout=20.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.1)
    fail(f"{what}: not within {timeout:.0f} s")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--source", required=True, type=Path)
    ap.add_argument("--build", required=True, type=Path)
    ap.add_argument("--jobs", default="1")
    args = ap.parse_args()
    source, build = args.source.resolve(), args.build.resolve()

    # What the browser half lacks, if anything: the site is built and checked all the same.
    missing = []
    try:
        import selenium  # noqa: F401
    except ImportError:
        missing.append("python3-selenium")
    for program, package in (("chromium", "chromium"), ("chromedriver", "chromium-driver")):
        if not shutil.which(program):
            missing.append(package)

    step("build the site (docs/build_site.py)")
    started = time.monotonic()
    built = subprocess.run([sys.executable, str(source / "docs/build_site.py"), "--source", str(source),
                            "--build", str(build), "--jobs", args.jobs])
    if built.returncode == SKIP:
        return SKIP
    if built.returncode != 0:
        fail(f"docs/build_site.py exited {built.returncode}")
    step(f"built in {time.monotonic() - started:.1f} s")
    html = build / "docs/html"
    if missing:
        print(f"docs_test: SKIPPED: the site was built and its links checked, but it was not opened: "
              f"{', '.join(missing)} not installed (scripts/setup.sh installs them)")
        return SKIP

    driver, why = browser()
    if driver is None:
        print(f"docs_test: SKIPPED: {why}")
        return SKIP
    try:
        from selenium.webdriver.common.by import By

        step("the front page (index.html leads to docs/index.html)")
        driver.get((html / "index.html").as_uri())
        wait_for(lambda: driver.current_url.endswith("docs/index.html"), "the redirect to docs/index.html")
        if "l6470emu" not in driver.title:
            fail(f"the front page's title is {driver.title!r}")
        guide = [a.get_attribute("href") for a in driver.find_elements(By.CSS_SELECTOR, "div.body a.reference.internal")]
        for page in ("guide/python.html", "guide/cpp.html", "reference/python-api.html", "reference/tables.html"):
            if not any(h and page in h for h in guide):
                fail(f"the front page does not link {page}")
        errors = console_errors(driver)
        if errors:
            fail(f"JavaScript errors on the front page: {errors}")

        # Read from disk, as /usr/share/doc/l6470emu/html is, and served, as a web site is.
        for base, how in ((html.as_uri(), "from disk"), (serve(html), "over HTTP on 127.0.0.1")):
            step(f"search: MAX_SPEED ({how})")
            driver.get(base + "/search.html?q=MAX_SPEED")
            summary = wait_for(lambda: [p for p in driver.find_elements(By.CSS_SELECTOR, "#search-results p.search-summary")
                                        if "found" in p.text], "the end of the search for MAX_SPEED")
            results = driver.find_elements(By.CSS_SELECTOR, "#search-results ul.search li")
            pages = [r.find_element(By.TAG_NAME, "a").get_attribute("href") for r in results]
            if not any("reference/tables.html" in p for p in pages):
                fail(f"searching MAX_SPEED does not find the register table ({summary[0].text}): {pages}")
            if base.startswith("http"):  # each page's result shows where the word is
                wait_for(lambda: driver.find_elements(By.CSS_SELECTOR, "#search-results ul.search li p.context"),
                         "the results' summaries")
            errors = console_errors(driver)
            if errors:
                fail(f"JavaScript errors on the search page ({how}): {errors}")
            print(f"   {len(results)} results")

        step("the Python API: l6470emu.Chain and its members")
        driver.get((html / "docs/reference/python-api.html").as_uri())
        chain = driver.find_element(By.ID, "l6470emu.Chain")
        members = chain.find_elements(By.XPATH, "./following-sibling::dd[1]//dt[starts-with(@id, 'l6470emu.Chain.')]")
        names = {m.get_attribute("id") for m in members}
        for needed in ("l6470emu.Chain.move", "l6470emu.Chain.advance", "l6470emu.Chain.get_status"):
            if needed not in names:
                fail(f"the Python API page shows l6470emu.Chain without {needed} ({len(names)} members)")
        if not chain.is_displayed():
            fail("l6470emu.Chain is not displayed")
        board = driver.find_elements(By.ID, "l6470emu.Board.attach_axis")
        if not board:
            fail("the Python API page lacks l6470emu.Board.attach_axis")
        errors = console_errors(driver)
        if errors:
            fail(f"JavaScript errors on the Python API page: {errors}")
        print(f"   l6470emu.Chain with {len(names)} members")

        step("the C++ API: l6470emu::Chain and its members")
        driver.get((html / "docs/reference/cpp/daisychain.html").as_uri())
        cls = driver.find_element(By.ID, "_CPPv4N8l6470emu5ChainE")
        members = cls.find_elements(By.XPATH, "./following-sibling::dd[1]//dt[starts-with(@id, '_CPPv4N8l6470emu5Chain')]")
        text = " ".join(m.text for m in members)
        for needed in ("advance_to", "frame", "chip"):
            if needed not in text:
                fail(f"the C++ API page shows l6470emu::Chain without {needed} ({len(members)} members)")
        if not cls.is_displayed():
            fail("l6470emu::Chain is not displayed")
        errors = console_errors(driver)
        if errors:
            fail(f"JavaScript errors on the C++ API page: {errors}")
        print(f"   l6470emu::Chain with {len(members)} members")

        step("the C API: l6470emu_fw_open")
        driver.get((html / "docs/reference/c-api.html").as_uri())
        if not driver.find_elements(By.ID, "c.l6470emu_fw_open"):
            fail("the C API page lacks l6470emu_fw_open")
        errors = console_errors(driver)
        if errors:
            fail(f"JavaScript errors on the C API page: {errors}")
    finally:
        driver.quit()
    print(f"docs_test: passed in {time.monotonic() - started:.1f} s: {html / 'index.html'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
