#!/usr/bin/python3
"""The report page's bound (docs/report.md, "Size"): records a long run of a 3-chip chain polled
every millisecond, writes its page with `l6470emu report`, and prints the trace's frames, the time
the report took, the page's size, and how long headless Chromium takes to open it. A measurement,
not a test: it prints numbers and asserts nothing.

Usage: bench/report_size.py BUILD_DIR [--minutes M] [--abs-pos] [--keep DIR]
  --minutes M  length of the run in simulated minutes (default 60)
  --abs-pos    also read every chip's ABS_POS at each poll: every answer differs while a motor
               moves, so nothing collapses (the worst case for the timeline)
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time

p = argparse.ArgumentParser()
p.add_argument("build")
p.add_argument("--minutes", type=float, default=60)
p.add_argument("--abs-pos", action="store_true")
p.add_argument("--keep")
a = p.parse_args()
sys.path.insert(0, os.path.join(a.build, "python"))
import l6470emu  # noqa: E402

work = a.keep or tempfile.mkdtemp(prefix="l6470emu-report-size-")
os.makedirs(work, exist_ok=True)
trace = os.path.join(work, "hour.trace.gz")
page = os.path.join(work, "hour.html")
ms = 4000  # ticks
started = time.monotonic()
with l6470emu.Chain(["L6470"] * 3, record=trace) as chain:
    for k in range(3):
        chain.get_status(k)
        chain.set_param(k, "MAX_SPEED", 0x20)
    polls = int(a.minutes * 60 * 1000)
    for i in range(polls):
        # Every 2 s one chip starts a move of its own length, back and forth.
        if i % 2000 == 0:
            k = (i // 2000) % 3
            chain.move(k, (i // 6000) % 2 == 0, 2000 + 700 * k)
        chain.frame(b"\xd0\xd0\xd0")
        chain.frame(b"\x00\x00\x00")
        chain.frame(b"\x00\x00\x00")
        if a.abs_pos:
            chain.frame(b"\x21\x21\x21")
            for _ in range(3):
                chain.frame(b"\x00\x00\x00")
        chain.advance_to((i + 1) * ms)
recorded = time.monotonic() - started
print("recorded %.0f simulated minutes in %.1f s: %s (%.1f MB)" % (a.minutes, recorded, trace, os.path.getsize(trace) / 1e6))

started = time.monotonic()
r = subprocess.run([os.path.join(a.build, "l6470emu"), "report", trace, "--max-frames", "0", "-o", page],
                   capture_output=True, text=True)
print(r.stderr.strip())
print("report took %.1f s; page %.2f MB" % (time.monotonic() - started, os.path.getsize(page) / 1e6))
if r.returncode != 0:
    sys.exit(1)

try:
    from selenium import webdriver
    from selenium.webdriver.chrome.options import Options
    from selenium.webdriver.chrome.service import Service
except ImportError:
    print("no python3-selenium: open time not measured")
    sys.exit(0)
o = Options()
for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1280,900"):
    o.add_argument(arg)
o.set_capability("goog:loggingPrefs", {"browser": "ALL"})
browser = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=o)
for attempt in range(3):
    browser.get("about:blank")
    started = time.monotonic()
    browser.get("file://" + os.path.abspath(page))
    while not browser.execute_script("return !!(window.l6470emuReport && window.l6470emuReport.readyMs)"):
        time.sleep(0.01)
    wall = time.monotonic() - started
    ready = browser.execute_script("return window.l6470emuReport.readyMs")
    print("open %d: drawn %.2f s after the navigation began (%.2f s as selenium saw it)" % (attempt + 1, ready / 1000, wall))
errors = [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
print("JavaScript errors: %s" % (errors or "none"))
browser.quit()
