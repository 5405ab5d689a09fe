#!/usr/bin/python3
"""`l6470emu report` pages in a real browser (Debian's chromium through chromium-driver and
python3-selenium): every fixture trace, and a campaign driver's clean run with its coverage
file and its campaign's JSON report. For each page: no JavaScript error and nothing loaded from
anywhere, the timeline holds as many frames as `decode` counts, the cursor moved to a known
instant (typed into the page's time box, as a person would) shows the ABS_POS and STATUS that
`decode` shows there, the arrow keys move it frame by frame and + zooms; `run --html` and
`campaign --html` write such pages too. A board of two chains gives one page with a section per
chain: each chain's timeline holds that chain's frames, and the cursor typed to a time on the
second chain shows the ABS_POS and STATUS `decode` shows in that chain's trace. Takes the screenshots
docs/report.md shows (L6470EMU_UPDATE_DOCS=1 writes them to docs/report.png and docs/report-chains.png).

Usage: report_browser_test.py L6470EMU SOURCE_DIR WORK_DIR CAMPAIGN_DRIVER
Exit 77 (skipped, with the reason) when chromium, chromedriver or selenium is missing."""
import glob
import os
import re
import shutil
import subprocess
import sys
import time

SKIP = 77


def skip(reason):
    print("SKIP: " + reason)
    sys.exit(SKIP)


try:
    from selenium import webdriver
    from selenium.webdriver.chrome.options import Options
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys
except ImportError:
    skip("python3-selenium is not installed (apt-get install python3-selenium)")

CHROMEDRIVER = shutil.which("chromedriver") or "/usr/bin/chromedriver"
if not os.path.exists(CHROMEDRIVER):
    skip("chromedriver is not installed (apt-get install chromium-driver)")
if not (shutil.which("chromium") or os.path.exists("/usr/bin/chromium")):
    skip("chromium is not installed (apt-get install chromium)")

l6470emu, source_dir, work, driver = sys.argv[1:5]
os.makedirs(work, exist_ok=True)
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def run(*args, cwd=None):
    return subprocess.run([l6470emu, *args], capture_output=True, text=True, timeout=300, cwd=cwd)


def decode_facts(trace):
    """Frame count, and per chip the last GetParam(ABS_POS) and the last GetStatus whose value no
    GetStatus changes (no latched flag), with their times as decode prints them."""
    out = run("decode", "--accept-divergence", trace).stdout
    frames = int(re.search(r"^# (\d+) frames?,", out, re.M).group(1))
    latched = re.compile(r"SW_EVN|NOTPERF_CMD|WRONG_CMD|CMD_ERROR|UVLO|TH_WRN|TH_SD|TH_WARNING|TH_BRIDGE|TH_DEVICE|OCD|STEP_LOSS|STALL")
    pos, status = {}, {}
    for m in re.finditer(r"^t=([0-9.]+) s  chip (\d+) +GetParam\(ABS_POS\) → 0x[0-9A-F]+ = (-?\d+) microsteps$", out, re.M):
        pos[int(m.group(2))] = (float(m.group(1)), int(m.group(3)))
    for m in re.finditer(r"^t=([0-9.]+) s  chip (\d+) +GetStatus → (0x[0-9A-F]{4}) \[([^\]]*)\]$", out, re.M):
        if not latched.search(m.group(4)):
            status[int(m.group(2))] = (float(m.group(1)), m.group(3))
    return frames, pos, status


options = Options()
for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1280,900",
          "--hide-scrollbars", "--force-device-scale-factor=1"):
    options.add_argument(a)
options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
try:
    browser = webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)
except Exception as e:  # a browser that cannot start is a failure, not a skip: it is installed
    print("FAIL chromium does not start: %s" % str(e).splitlines()[0])
    sys.exit(1)


def open_page(path):
    browser.get("file://" + os.path.abspath(path))
    for _ in range(100):
        if browser.execute_script("return !!window.l6470emuReport"):
            break
        time.sleep(0.05)
    return browser.find_element(By.TAG_NAME, "body")


def errors():
    return [e for e in browser.get_log("browser") if e["level"] in ("SEVERE", "ERROR")]


def goto(seconds, box_id="goto-time"):
    box = browser.find_element(By.ID, box_id)
    box.clear()
    box.send_keys("%.7f" % seconds, Keys.ENTER)


def text(element_id):
    return browser.find_element(By.ID, element_id).text


def check_page(name, trace, page):
    frames, pos, status = decode_facts(trace)
    body = open_page(page)
    check(not errors(), "%s: no JavaScript error (%s)" % (name, errors() or "none"))
    loaded = browser.execute_script("return performance.getEntriesByType('resource').length")
    check(loaded == 0, "%s: the page loads nothing (%d resources)" % (name, loaded))
    check(text("frame-count") == "%d frames" % frames, "%s: the timeline holds %d frames (%s)" % (name, frames, text("frame-count")))
    check(browser.execute_script("return l6470emuReport.frames()") == frames, "%s: the script counts %d frames" % (name, frames))
    # decode prints times rounded to the microsecond: half of one more lands inside the frame.
    for chip, (t, value) in sorted(pos.items()):
        goto(t + 0.5e-6)
        shown = text("reg-%d-ABS_POS" % chip)
        check(shown == str(value), "%s: at t=%.6f s chip %d ABS_POS is %d (shown %s)" % (name, t, chip, value, shown))
    for chip, (t, value) in sorted(status.items()):
        goto(t + 0.5e-6)
        shown = text("status-%d" % chip)
        check(shown == value, "%s: at t=%.6f s chip %d STATUS is %s (shown %s)" % (name, t, chip, value, shown))
    # The keyboard: → moves one frame on, + zooms in around the cursor.
    browser.execute_script("l6470emuReport.setCursor(0)")
    before = browser.execute_script("return l6470emuReport.cursor().frame")
    width = browser.execute_script("return l6470emuReport.window()[1] - l6470emuReport.window()[0]")
    body.send_keys(Keys.ARROW_RIGHT)
    body.send_keys("+")
    after = browser.execute_script("return l6470emuReport.cursor().frame")
    narrower = browser.execute_script("return l6470emuReport.window()[1] - l6470emuReport.window()[0]")
    check(after == min(before + 1, frames - 1), "%s: → moves the cursor to the next frame (%d → %d)" % (name, before, after))
    check(narrower < width, "%s: + zooms in (%.6f s → %.6f s)" % (name, width, narrower))
    check(not errors(), "%s: still no JavaScript error" % name)


traces = sorted(glob.glob(os.path.join(source_dir, "fixtures", "traces", "*.trace")))
check(len(traces) >= 3, "fixture traces found: %d" % len(traces))
for trace in traces:
    name = os.path.basename(trace)
    page = os.path.join(work, name + ".html")
    r = run("report", trace, "-o", page)
    check(r.returncode == 0, "%s: report writes the page (%s)" % (name, r.stderr.strip()))
    if r.returncode == 0:
        check_page(name, trace, page)

# A campaign driver: its campaign's JSON, its clean run's trace and coverage, on one page.
camp = os.path.join(work, "campaign")
shutil.rmtree(camp, ignore_errors=True)
os.makedirs(camp)
subprocess.run([l6470emu, "campaign", "--chain", "chips=L6470", "--faults", "ocd,uvlo,sw_close", "--json",
                os.path.join(camp, "campaign.json"), "--", driver], cwd=camp, capture_output=True, timeout=300)
r = run("run", "--chain", "chips=L6470", "--record", os.path.join(camp, "clean.trace"), "--coverage",
        os.path.join(camp, "coverage.json"), "--", driver)
check(r.returncode == 0, "the campaign driver's clean run (%s)" % r.stderr.strip().splitlines()[-1:])
page = os.path.join(work, "campaign.html")
r = run("report", os.path.join(camp, "clean.trace"), "--coverage", os.path.join(camp, "coverage.json"), "--campaign",
        os.path.join(camp, "campaign.json"), "-o", page)
check(r.returncode == 0, "report with --coverage and --campaign (%s)" % r.stderr.strip())
if r.returncode == 0:
    check_page("campaign driver", os.path.join(camp, "clean.trace"), page)
    reruns = len(browser.find_elements(By.CSS_SELECTOR, "#reruns tbody tr"))
    check(reruns > 0, "the campaign's reruns are listed (%d)" % reruns)
    commands = [c.text for c in browser.find_elements(By.CSS_SELECTOR, "#reruns tbody tr td code")]
    check(all(c.startswith("l6470emu run ") for c in commands), "every rerun has its reproducing command")
    links = browser.find_elements(By.CSS_SELECTOR, "table.matrix a[href^='#rerun-']")
    check(len(links) == reruns, "every matrix cell links to its rerun (%d links)" % len(links))
    check("Interface coverage:" in browser.find_element(By.ID, "coverage").text, "the coverage report is on the page")

# run --html and campaign --html write the same pages in one go.
page = os.path.join(work, "run.html")
r = run("run", "--chain", "chips=L6470", "--record", os.path.join(camp, "run.trace"), "--html", page, "--", driver)
check(r.returncode == 0 and os.path.exists(page), "run --html writes the page (%s)" % r.stderr.strip().splitlines()[-1:])
if os.path.exists(page):
    check_page("run --html", os.path.join(camp, "run.trace"), page)
page = os.path.join(work, "campaign-html.html")
r = subprocess.run([l6470emu, "campaign", "--chain", "chips=L6470", "--faults", "ocd,uvlo", "--html", page, "--", driver],
                   cwd=camp, capture_output=True, text=True, timeout=300)
check(os.path.exists(page) and "campaign --html: " in r.stderr, "campaign --html writes the page (%s)" % r.stderr.strip().splitlines()[-1:])
if os.path.exists(page):
    open_page(page)
    check(not errors(), "campaign --html: no JavaScript error")
    check(len(browser.find_elements(By.CSS_SELECTOR, "table.matrix a[href^='#rerun-']")) > 0, "campaign --html: the matrix is on the page")

# A board of two chains (one chip on spidev0.0, two on spidev0.1): one page, a section per chain.
TWO_CHAIN_DRIVER = """import spidev, time
def dev(cs):
    s = spidev.SpiDev(); s.open(0, cs); s.mode = 3; s.max_speed_hz = 1000000; return s
a, b = dev(0), dev(1)
x = lambda s, *frames: [s.xfer2(list(f)) for f in frames]
x(a, [0xD0], [0], [0])
x(b, [0xD0, 0xD0], [0, 0], [0, 0])
x(b, [0x41, 0x41], [0, 0], [0x0C, 0x06], [0x80, 0x40])
x(a, [0x21], [0], [0], [0])
time.sleep(1)
x(b, [0x21, 0x21], [0, 0], [0, 0], [0, 0])
x(b, [0xD0, 0xD0], [0, 0], [0, 0])
x(a, [0xD0], [0], [0])
"""
two = os.path.join(work, "two-chains")
shutil.rmtree(two, ignore_errors=True)
os.makedirs(two)
with open(os.path.join(two, "driver.py"), "w") as f:
    f.write(TWO_CHAIN_DRIVER)
page = os.path.join(two, "two-chains.html")
r = run("run", "--chain", "bus=0 cs=0 chips=L6470; bus=0 cs=1 chips=2xL6470", "--record", "run.trace", "--html", "two-chains.html",
        "--", "/usr/bin/python3", "driver.py", cwd=two)
check(r.returncode == 0 and os.path.exists(page), "run --html on two chains writes the page (%s)" % r.stderr.strip().splitlines()[-1:])
if os.path.exists(page):
    name = "two chains"
    traces = [os.path.join(two, "run.spidev0.0.trace"), os.path.join(two, "run.spidev0.1.trace")]
    facts = [decode_facts(t) for t in traces]
    body = open_page(page)
    check(not errors(), "%s: no JavaScript error (%s)" % (name, errors() or "none"))
    loaded = browser.execute_script("return performance.getEntriesByType('resource').length")
    check(loaded == 0, "%s: the page loads nothing (%d resources)" % (name, loaded))
    check(browser.execute_script("return l6470emuReport.chains()") == 2, "%s: the page has two chains" % name)
    total = sum(f[0] for f in facts)
    check(text("frame-count") == "%d frames" % total, "%s: the page holds %d frames (%s)" % (name, total, text("frame-count")))
    for k, (frames, _, _) in enumerate(facts):
        shown = text("chain%d-frame-count" % k)
        check(shown == "%d frames" % frames, "%s: chain %d's timeline holds its %d frames (%s)" % (name, k, frames, shown))
        counted = browser.execute_script("return l6470emuReport.chainFrames(%d)" % k)
        check(counted == frames, "%s: the script counts %d frames on chain %d (%s)" % (name, frames, k, counted))
    check(text("chain1").startswith("Chain spidev0.1 (bus 0, cs 1)"), "%s: the second section is spidev0.1 (%s)" % (name, text("chain1")))
    _, pos, status = facts[1]
    check(any(v != 0 for _, v in pos.values()), "%s: the second chain's chips moved (%s)" % (name, pos))
    for chip, (t, value) in sorted(pos.items()):
        goto(t + 0.5e-6, "chain1-goto-time")
        shown = text("chain1-reg-%d-ABS_POS" % chip)
        check(shown == str(value), "%s: at t=%.6f s spidev0.1 chip %d ABS_POS is %d (shown %s)" % (name, t, chip, value, shown))
        check(browser.execute_script("return l6470emuReport.cursor().chain") == 1, "%s: the second chain's box moves its cursor" % name)
        check(text("chain0-reg-0-ABS_POS") == "0", "%s: spidev0.0 at that instant shows its own chip (ABS_POS %s)" % (name, text("chain0-reg-0-ABS_POS")))
    for chip, (t, value) in sorted(status.items()):
        goto(t + 0.5e-6, "chain1-goto-time")
        shown = text("chain1-status-%d" % chip)
        check(shown == value, "%s: at t=%.6f s spidev0.1 chip %d STATUS is %s (shown %s)" % (name, t, chip, value, shown))
    before = browser.execute_script("return l6470emuReport.cursor().frame")
    body.send_keys(Keys.ARROW_LEFT)
    cur = browser.execute_script("return l6470emuReport.cursor()")
    check(cur["chain"] == 1 and cur["frame"] == max(before - 1, 0), "%s: ← moves the cursor on the chain last used (%s)" % (name, cur))
    check(not errors(), "%s: still no JavaScript error" % name)
    # The screenshot docs/report.md shows of it: the second chain's section, the cursor on its Moves.
    goto(0.000210 + 0.5e-6, "chain1-goto-time")
    for _ in range(12):
        body.send_keys("+")
    browser.execute_script("document.getElementById('chain1').scrollIntoView()")
    shot = os.path.join(work, "report-chains.png")
    browser.set_window_size(1280, 1000)
    browser.save_screenshot(shot)
    browser.set_window_size(1280, 900)
    check(os.path.getsize(shot) > 10000, "screenshot taken: " + shot)
    if os.environ.get("L6470EMU_UPDATE_DOCS") == "1":
        shutil.copyfile(shot, os.path.join(source_dir, "docs", "report-chains.png"))
        print("wrote docs/report-chains.png")

# The screenshot the docs show: three chips, the cursor on the Move commands, zoomed in.
page = os.path.join(work, "docs.html")
r = run("report", "fixtures/traces/three_chips.trace", "-o", os.path.abspath(page), cwd=source_dir)
if r.returncode == 0:
    body = open_page(page)
    goto(0.0010825)
    for _ in range(3):
        body.send_keys("+")
    browser.execute_script("window.scrollTo(0, 0)")
    shot = os.path.join(work, "report.png")
    browser.save_screenshot(shot)
    check(os.path.getsize(shot) > 10000, "screenshot taken: " + shot)
    if os.environ.get("L6470EMU_UPDATE_DOCS") == "1":
        shutil.copyfile(shot, os.path.join(source_dir, "docs", "report.png"))
        print("wrote docs/report.png")

browser.quit()
if failures:
    print("report browser test: %d check(s) failed" % len(failures))
    sys.exit(1)
print("report browser test: every check passed")
