#!/usr/bin/env python3
"""The playground (`GET /` of `bondmech serve`, issue 37) in a real browser: headless Chromium
(Debian's `chromium` and `chromium-driver`) driven by Selenium (PyPI).

Usage: playground_browser.py BONDMECH_EXE SCREENSHOT_DIR

Starts `bondmech serve --addr 127.0.0.1:0` (the address read from its first line), opens the
page and works through it as a person would: pick a scene, run, scrub the time slider, compare,
a spatial scene, a raw bond graph, a scene that fails to solve, a bad scene, a cancelled long
run, and a scene whose name is markup. The references are independent of the page: the command
line's own error lines, the service's JSON, and the DOM and network log of the browser.
Screenshots go to SCREENSHOT_DIR. Exits non-zero on the first failed check.
"""

import json
import os
import re
import subprocess
import sys
import tempfile
import time
import urllib.request

from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select, WebDriverWait

EXE, SHOTS = sys.argv[1], sys.argv[2]
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def check(cond, what):
    if not cond:
        raise AssertionError(what)
    print("ok:", what)


def start_server():
    p = subprocess.Popen(
        [EXE, "serve", "--addr", "127.0.0.1:0", "--max-concurrent", "2"],
        stderr=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
        text=True,
    )
    line = p.stderr.readline()
    m = re.search(r"serving on (http://[0-9.:]+)", line)
    if not m:
        p.kill()
        raise AssertionError(f"bondmech serve did not start: {line!r}")
    return p, m.group(1)


def browser():
    opts = webdriver.ChromeOptions()
    opts.binary_location = next(
        b for b in ("/usr/bin/chromium", "/usr/bin/chromium-browser") if os.path.exists(b)
    )
    for a in (
        "--headless=new",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-dev-shm-usage",
        "--window-size=1500,1650",
        "--force-device-scale-factor=1",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-default-apps",
        "--disable-sync",
        "--metrics-recording-only",
        "--disable-features=Translate,OptimizationHints,MediaRouter",
    ):
        opts.add_argument(a)
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL", "performance": "ALL"})
    downloads = tempfile.mkdtemp(prefix="bondmech-playground-dl-")
    opts.add_experimental_option(
        "prefs", {"download.default_directory": downloads, "download.prompt_for_download": False}
    )
    driver_path = next(
        (d for d in ("/usr/bin/chromedriver", "/usr/lib/chromium/chromedriver") if os.path.exists(d)),
        None,
    )
    service = Service(executable_path=driver_path) if driver_path else Service()
    return webdriver.Chrome(options=opts, service=service), downloads


def wait(driver, cond, what, timeout=30):
    try:
        return WebDriverWait(driver, timeout, poll_frequency=0.02).until(lambda d: cond(d))
    except Exception as e:
        raise AssertionError(f"timed out waiting for {what}") from e


def state(driver):
    return driver.execute_script("return document.body.dataset.state || ''")


def set_editor(driver, text):
    # the page's contract: setting the textarea's value and dispatching `input` takes effect
    driver.execute_script(
        "var e = document.getElementById('editor'); e.value = arguments[0];"
        "e.dispatchEvent(new Event('input'));",
        text,
    )


def problems(driver):
    # one script call: the list is rebuilt as validations answer (no stale element handles)
    return driver.execute_script(
        "return Array.from(document.querySelectorAll('#problems li')).map(li => li.textContent)"
    )


def wait_valid(driver):
    wait(
        driver,
        lambda d: d.execute_script("return document.getElementById('problems').dataset.valid") == "true",
        "the scene to validate",
    )


def run(driver, expect="done", timeout=60):
    driver.execute_script("document.body.dataset.state = ''")
    t = time.perf_counter()
    driver.find_element(By.ID, "run").click()
    wait(driver, lambda d: state(d) in ("done", "failed", "cancelled"), "the run to end", timeout)
    elapsed = time.perf_counter() - t
    check(state(driver) == expect, f"the run ends {expect} (is {state(driver)})")
    return elapsed


def pick(driver, name):
    Select(driver.find_element(By.ID, "scene-picker")).select_by_value(name)
    text = open(os.path.join(ROOT, "scenes", name + ".json")).read()
    wait(
        driver,
        lambda d: d.execute_script("return document.getElementById('editor').value") == text,
        f"{name} in the editor",
    )
    wait_valid(driver)


def shot(driver, name):
    path = os.path.join(SHOTS, name + ".png")
    driver.save_screenshot(path)
    print("screenshot:", path)


def console_errors(driver, allowed=()):
    bad = []
    for e in driver.get_log("browser"):
        if e["level"] in ("SEVERE", "ERROR") and not any(a in e["message"] for a in allowed):
            bad.append(e["message"])
    return bad


def requests_sent(driver):
    urls = []
    for e in driver.get_log("performance"):
        m = json.loads(e["message"])["message"]
        if m.get("method") == "Network.requestWillBeSent":
            urls.append(m["params"]["request"]["url"])
    return urls


def cli_errors(scene_text):
    """The command line's error lines for a scene (the reference for the problems list)."""
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        f.write(scene_text)
    out = subprocess.run([EXE, "run", f.name, "--t-end", "0.01"], capture_output=True, text=True)
    os.unlink(f.name)
    return out.returncode, out.stderr


def main():
    os.makedirs(SHOTS, exist_ok=True)
    server, origin = start_server()
    driver = None
    try:
        # the page's headers: a strict policy, nothing from another origin
        with urllib.request.urlopen(origin + "/") as r:
            csp = r.headers["Content-Security-Policy"]
        check(csp and "default-src 'none'" in csp and "script-src 'self'" in csp, f"GET / sends a CSP ({csp})")
        check("http" not in csp.replace(origin, ""), "the CSP names no other origin")

        driver, downloads = browser()
        t = time.perf_counter()
        driver.get(origin + "/")
        wait(driver, lambda d: d.execute_script("return document.body.dataset.ready") == "true", "the page")
        load = time.perf_counter() - t
        nav = driver.execute_script(
            "var n = performance.getEntriesByType('navigation')[0]; return n.loadEventEnd - n.startTime;"
        )
        print(f"measured: page ready in {load * 1e3:.0f} ms (load event at {nav:.0f} ms)")
        for id_ in ("scene-picker", "editor", "problems", "run", "compare", "summary", "plot",
                    "animation", "time", "play", "graph", "csv", "verdict"):
            check(len(driver.find_elements(By.ID, id_)) == 1, f"#{id_} is on the page")
        check(driver.find_element(By.ID, "time").get_attribute("type") == "range", "#time is a range input")
        with urllib.request.urlopen(origin + "/v1/scenes") as r:
            names = json.load(r)
        options = [o.get_attribute("value") for o in driver.find_elements(By.CSS_SELECTOR, "#scene-picker option")
                   if o.get_attribute("value")]
        expected = sorted(f[:-5] for f in os.listdir(os.path.join(ROOT, "scenes")) if f.endswith(".json"))
        check(names == expected and options == expected, "the picker lists scenes/*.json by name")

        # ---- a planar scene: run, then summary, plot, animation and graph
        pick(driver, "double_pendulum")
        elapsed = run(driver)
        print(f"measured: double pendulum run shown {elapsed * 1e3:.0f} ms after the click "
              f"(page's own clock {driver.execute_script('return document.body.dataset.runMs')} ms)")
        summary = driver.find_element(By.ID, "summary").text
        for field in ("formulation", "states", "steps", "CPU", "energy drift", "warnings"):
            check(field in summary, f"the summary shows {field}")
        check(len(driver.find_elements(By.CSS_SELECTOR, "#plot svg polyline.series")) >= 1, "the plot has curves")
        anim = driver.find_elements(By.CSS_SELECTOR, "#animation svg.bondmech-animation")
        check(len(anim) == 1, "the animation is an inline SVG")
        graph_texts = driver.execute_script(
            "return Array.from(document.querySelectorAll('#graph svg text')).map(t => t.textContent)"
        )
        check(len(graph_texts) > 5, f"the bond graph is an inline SVG with labels ({len(graph_texts)} texts)")
        check(len(driver.find_elements(By.CSS_SELECTOR, "#graph svg path, #graph svg polyline, #graph svg polygon")) > 5,
              "the bond graph has bonds drawn")
        shot(driver, "double_pendulum")

        # ---- scrub: the bodies move with the slider, and the readout follows
        def pose():
            return driver.execute_script(
                "return Array.from(document.querySelectorAll('#animation g.body')).map(function (g) {"
                " var r = g.getBoundingClientRect(); return [r.x, r.y, r.width, r.height]; })"
            )

        def scrub(t):
            driver.execute_script(
                "var s = document.getElementById('time'); s.value = arguments[0];"
                "s.dispatchEvent(new Event('input'));",
                t,
            )
            time.sleep(0.1)

        slider = driver.find_element(By.ID, "time")
        t0, t1 = float(slider.get_attribute("min")), float(slider.get_attribute("max"))
        check(t1 > t0, f"the slider spans the motion ({t0} to {t1} s)")
        scrub(t0)
        a = pose()
        png_a = driver.find_element(By.ID, "animation").screenshot_as_png
        scrub(t0 + 0.5 * (t1 - t0))
        b = pose()
        png_b = driver.find_element(By.ID, "animation").screenshot_as_png
        bodies = driver.execute_script(
            "return new Set(Array.from(document.querySelectorAll('#animation g.body')).map(g => g.dataset.body)).size"
        )
        check(bodies == 2 and len(a) == len(b) >= 2, f"two bodies drawn ({len(a)} groups)")
        moved = max(abs(x - y) for pa, pb in zip(a, b) for x, y in zip(pa, pb))
        check(moved > 5, f"scrubbing to mid-motion moves the bodies ({moved:.0f} px)")
        check(png_a != png_b, "the picture changes with the slider")
        readout = driver.find_element(By.ID, "time-readout").text
        check(readout.startswith("t = ") and abs(float(readout.split()[2]) - 0.5 * (t0 + t1)) < 0.01,
              f"the readout follows the slider ({readout})")
        scrub(t0)
        check(max(abs(x - y) for pa, pc in zip(a, pose()) for x, y in zip(pa, pc)) < 0.5,
              "scrubbing back to the start puts the bodies back")
        scrub(t0 + 0.37 * (t1 - t0))
        shot(driver, "scrubbed")
        # play: the time advances by itself
        before = driver.find_element(By.ID, "time-readout").text
        driver.find_element(By.ID, "play").click()
        time.sleep(0.4)
        after = driver.find_element(By.ID, "time-readout").text
        driver.find_element(By.ID, "play").click()
        check(before != after, f"play advances the time ({before} → {after})")

        # ---- CSV download: the service's CSV, header first
        driver.find_element(By.ID, "csv").click()
        wait(driver, lambda d: any(f.endswith(".csv") for f in os.listdir(downloads)), "the CSV download")
        csv_file = next(f for f in os.listdir(downloads) if f.endswith(".csv"))
        time.sleep(0.2)
        downloaded = open(os.path.join(downloads, csv_file)).read()
        cli_csv = subprocess.run([EXE, "run", os.path.join(ROOT, "scenes/double_pendulum.json")],
                                 capture_output=True, text=True, check=True).stdout
        check(downloaded == cli_csv, f"the CSV download is `bondmech run`'s CSV ({csv_file}, {len(cli_csv)} bytes)")

        # ---- compare: the verdict and the twin overlaid on the plot
        driver.execute_script("document.body.dataset.state = ''")
        driver.find_element(By.ID, "compare").click()
        wait(driver, lambda d: state(d) in ("compared", "failed"), "the comparison")
        verdict = driver.find_element(By.ID, "verdict").text
        with urllib.request.urlopen(urllib.request.Request(
                origin + "/v1/compare", data=open(os.path.join(ROOT, "scenes/double_pendulum.json"), "rb").read(),
                headers={"Content-Type": "application/json"})) as r:
            reference = json.load(r)["verdict"]
        check(("recommended: " + reference["recommended"]) in verdict, f"the verdict is the service's ({verdict.splitlines()[0]})")
        check(len(driver.find_elements(By.CSS_SELECTOR, "#plot svg polyline.twin")) >= 1,
              "the twin's motion is overlaid on the plot")
        wait(driver, lambda d: d.find_elements(By.CSS_SELECTOR, "#animation svg.twin-overlay"), "the twin's animation")
        scrub(t0 + 0.66 * (t1 - t0))

        def rects(sel):
            return driver.execute_script(
                "return Array.from(document.querySelectorAll(arguments[0])).map(function (g) {"
                " var r = g.getBoundingClientRect(); return [r.x, r.y, r.width, r.height]; })", sel)
        dae = rects("#animation svg:not(.twin-overlay) g.body")
        twin = rects("#animation svg.twin-overlay g.body")
        off = max(abs(x - y) for pa, pb in zip(dae, twin) for x, y in zip(pa, pb))
        # the verdict's largest position difference is ~1e-5 m: under a pixel at this scale
        check(len(dae) == len(twin) >= 2 and off < 1.5,
              f"the twin's animation is overlaid on the DAE's and follows the slider ({off:.2f} px apart)")
        shot(driver, "compare")

        # ---- the bond graph zooms and pans (buttons, wheel, drag)
        from selenium.webdriver.common.action_chains import ActionChains

        def viewbox():
            return [float(x) for x in driver.execute_script(
                "return document.querySelector('#graph svg').getAttribute('viewBox')").split()]
        fit = viewbox()
        for _ in range(3):
            driver.find_element(By.ID, "graph-zoom-in").click()
        zoomed = viewbox()
        check(abs(zoomed[2] - fit[2] / 1.4 ** 3) < 1e-6 * fit[2], f"+ zooms the bond graph in ({fit[2]:.0f} → {zoomed[2]:.0f} wide)")
        driver.execute_script(
            "var g = document.getElementById('graph'), r = g.getBoundingClientRect();"
            "g.dispatchEvent(new WheelEvent('wheel', {deltaY: 100, clientX: r.left + r.width / 2,"
            " clientY: r.top + r.height / 2, bubbles: true, cancelable: true}));")
        wheeled = viewbox()
        check(abs(wheeled[2] - zoomed[2] * 1.15) < 1e-6 * fit[2], "the wheel zooms it out about the pointer")
        zoomed = wheeled
        g = driver.find_element(By.ID, "graph")
        ActionChains(driver).move_to_element(g).click_and_hold().move_by_offset(-120, -60).release().perform()
        panned = viewbox()
        check(panned[0] > zoomed[0] and panned[1] > zoomed[1] and panned[2] == zoomed[2], "dragging pans it")
        driver.execute_script("document.getElementById('graph').scrollIntoView()")
        shot(driver, "graph_zoomed")
        driver.find_element(By.ID, "graph-reset").click()
        check(viewbox() == fit, "fit puts the whole graph back")
        driver.execute_script("window.scrollTo(0, 0)")

        errors = console_errors(driver)
        check(not errors, f"no console errors so far {errors}")

        # ---- a spatial scene: the 3D view (shaded bodies on a canvas, orbit and zoom)
        pick(driver, "hinged_double_pendulum_3d")
        run(driver)
        views = driver.execute_script(
            "return Array.from(document.querySelectorAll('#animation canvas, #animation svg')).map(s => s.getAttribute('data-view'))"
        )
        check(views == ["3d"], f"a spatial scene is drawn in the 3D view, on a canvas ({views})")
        # the canvas's pixels: how many are not the white background, and a digest of them
        pixels = (
            "var c = document.querySelector('#animation canvas'), g = c.getContext('2d');"
            "var d = g.getImageData(0, 0, c.width, c.height).data, n = 0, h = 0;"
            "for (var i = 0; i < d.length; i += 4) { if (d[i] < 250 || d[i+1] < 250 || d[i+2] < 250) n++;"
            " h = (h * 31 + d[i] + 7 * d[i+1] + 13 * d[i+2]) % 1000000007; }"
            "return [n / (c.width * c.height), h];"
        )
        inked, start = driver.execute_script(pixels)
        check(inked > 0.01, f"the 3D view draws the bodies ({inked:.3f} of the canvas inked)")
        t1 = float(driver.find_element(By.ID, "time").get_attribute("max"))
        scrub(0.5 * t1)
        _, middle = driver.execute_script(pixels)
        readout = driver.find_element(By.ID, "time-readout").text
        check(middle != start and readout.startswith("t = "), f"scrubbing moves the 3D view ({readout})")
        driver.execute_script("document.getElementById('animation').scrollIntoView()")
        shot(driver, "spatial")
        driver.execute_script("window.scrollTo(0, 0)")
        canvas = driver.find_element(By.CSS_SELECTOR, "#animation canvas")
        ActionChains(driver).move_to_element(canvas).click_and_hold().move_by_offset(80, 30).release().perform()
        _, orbited = driver.execute_script(pixels)
        check(orbited != middle and driver.find_element(By.ID, "time-readout").text == readout,
              "dragging orbits the camera, at the same time")
        driver.find_element(By.ID, "play").click()
        time.sleep(0.4)
        driver.find_element(By.ID, "play").click()
        moved = driver.find_element(By.ID, "time-readout").text
        check(moved != readout, f"play runs the 3D view's clock ({readout} → {moved})")
        # the twin of a spatial scene is slow (stiff springs on six coordinates per body): one second
        driver.execute_script("var e = document.getElementById('t_end'); e.value = '1';"
                              "e.dispatchEvent(new Event('input')); e.dispatchEvent(new Event('change'));")
        driver.find_element(By.ID, "compare").click()
        wait(driver, lambda d: state(d) in ("compared", "failed"), "the 3D comparison", timeout=120)
        check(state(driver) == "compared",
              "compare works on the spatial scene (status: " + driver.find_element(By.ID, "status").text
              + "; verdict: " + driver.find_element(By.ID, "verdict").text
              + "; error: " + driver.find_element(By.ID, "run-error").text + ")")
        check("twin" in driver.find_element(By.ID, "animation").text,
              "the twin's motion is drawn in the 3D view, faded (the page says so)")
        driver.execute_script("var e = document.getElementById('t_end'); e.value = '';"
                              "e.dispatchEvent(new Event('input')); e.dispatchEvent(new Event('change'));")
        errors = console_errors(driver)
        check(not errors, f"no console errors in 3D {errors}")

        # ---- a raw bond graph: no animation, and the page says so
        pick(driver, "bg_dc_motor")
        run(driver)
        check("no animation" in driver.find_element(By.ID, "animation").text, "a raw bond graph: the page says there is no animation")
        check(driver.find_element(By.ID, "time").get_attribute("disabled") is not None, "…and the slider is off")
        check(len(driver.find_elements(By.CSS_SELECTOR, "#graph svg")) == 1, "…its bond graph is drawn")
        check("formulation" in driver.find_element(By.ID, "summary").text, "…its summary is shown")
        shot(driver, "bond_graph")
        errors = console_errors(driver)
        check(not errors, f"no console errors {errors}")

        # ---- a scene that fails to solve: the error and the rows computed before it
        failing = json.load(open(os.path.join(ROOT, "scenes/double_pendulum.json")))
        failing["solve"]["max_steps"] = 40
        set_editor(driver, json.dumps(failing, indent=2))
        wait_valid(driver)
        run(driver, expect="failed")
        err = driver.find_element(By.ID, "run-error")
        check(err.is_displayed() and "max_steps" in err.text, f"the failure is shown ({err.text.splitlines()[0]})")
        rows = driver.execute_script("return document.querySelectorAll('#plot svg polyline.series').length")
        partial = driver.find_element(By.ID, "summary").text
        check(rows >= 1 and "partial" in partial, f"the partial rows are plotted and counted ({partial.splitlines()})")
        shot(driver, "failed")
        check("no animation" in driver.find_element(By.ID, "animation").text, "…and no animation of a run that failed")
        errors = console_errors(driver)
        check(not errors, f"no console errors {errors}")

        # ---- a bad scene: the problems list names the JSON path, as the command line does
        bad = json.load(open(os.path.join(ROOT, "scenes/double_pendulum.json")))
        bad["bodies"][0]["mass"] = -1.0
        bad_text = json.dumps(bad, indent=2)
        set_editor(driver, bad_text)
        wait(driver, lambda d: any("bodies[0].mass" in p for p in problems(d)), "the problem with its JSON path")
        code, cli_err = cli_errors(bad_text)
        listed = problems(driver)
        check(code != 0 and all(p in cli_err for p in listed),
              f"the problems are the command line's lines ({listed})")
        shot(driver, "problems")
        # malformed JSON: line and column
        set_editor(driver, bad_text[:40])
        try:
            wait(driver, lambda d: any("line" in p for p in problems(d)), "a malformed-JSON problem with its line", 10)
        except AssertionError:
            raise AssertionError(f"no malformed-JSON problem with its line: {problems(driver)}")

        # ---- a scene cannot inject markup: names with <script> are shown as text
        evil = json.load(open(os.path.join(ROOT, "scenes/pendulum.json")))
        evil["name"] = "<script>window.__pwned = 1</script><img id=\"injected\" src=\"x\">"
        set_editor(driver, json.dumps(evil, indent=2))
        wait_valid(driver)
        run(driver)
        check(driver.execute_script("return window.__pwned === undefined"), "the scene's <script> did not run")
        check(not driver.find_elements(By.ID, "injected"), "the scene's <img> is not an element of the page")
        check(driver.find_element(By.ID, "scene-name").text == evil["name"], "the name is shown as text")
        title = driver.execute_script("return document.querySelector('#animation svg title').textContent")
        check(evil["name"] in title, "the animation's title holds the name as text")
        evil2 = json.load(open(os.path.join(ROOT, "scenes/double_pendulum.json")))
        evil2["joints"][1]["bodies"][0] = "<b id=\"injected2\">bar1</b>"
        set_editor(driver, json.dumps(evil2, indent=2))
        wait(driver, lambda d: any("injected2" in p for p in problems(d)), "the markup-named body's problem")
        check(not driver.find_elements(By.ID, "injected2"), "a body name in a problem is shown as text")
        scripts = driver.execute_script("return Array.from(document.scripts).map(s => s.getAttribute('src'))")
        check(scripts == ["/view3d.js", "/playground.js"], f"the page's own two scripts, no other ({scripts})")
        shot(driver, "injection")

        # ---- a long run: progress, the page stays usable (validation answers), cancel
        long = json.load(open(os.path.join(ROOT, "scenes/double_pendulum.json")))
        long["solve"]["t_end"] = 900.0
        long["solve"]["output_step"] = 0.01
        set_editor(driver, json.dumps(long, indent=2))
        wait_valid(driver)
        with urllib.request.urlopen(origin + "/metrics") as r:
            cancelled_before = float(re.search(r"^bondmech_solves_cancelled_total (\S+)$", r.read().decode(), re.M).group(1))
        driver.execute_script("document.body.dataset.state = ''")
        driver.find_element(By.ID, "run").click()
        wait(driver, lambda d: float(d.find_element(By.ID, "progress").get_attribute("value")) > 0,
             "progress during the long run")
        p1 = float(driver.find_element(By.ID, "progress").get_attribute("value"))
        bad_while_busy = dict(long)
        bad_while_busy["gravity"] = [0.0]
        set_editor(driver, json.dumps(bad_while_busy, indent=2))
        wait(driver, lambda d: any("gravity" in p for p in problems(d)), "validation while a solve runs", 5)
        time.sleep(0.3)
        p2 = float(driver.find_element(By.ID, "progress").get_attribute("value"))
        check(0 < p1 < p2 < 1, f"progress advances ({p1:.4f} → {p2:.4f})")
        shot(driver, "long_run")
        driver.find_element(By.ID, "cancel").click()
        wait(driver, lambda d: state(d) == "cancelled", "the cancel")

        def cancelled_now():
            with urllib.request.urlopen(origin + "/metrics") as r:
                return float(re.search(r"^bondmech_solves_cancelled_total (\S+)$", r.read().decode(), re.M).group(1))
        deadline = time.time() + 10
        while cancelled_now() <= cancelled_before and time.time() < deadline:
            time.sleep(0.05)
        check(cancelled_now() > cancelled_before, "the server stopped the cancelled solve")

        # ---- nothing left the origin; no console errors but the failed run's answer
        urls = requests_sent(driver)
        outside = [u for u in urls if not (u.startswith(origin + "/") or u.startswith("blob:" + origin) or u.startswith("data:"))]
        check(urls and not outside, f"{len(urls)} requests, none outside {origin} {outside}")
        entries = driver.execute_script(
            "return performance.getEntriesByType('resource').map(e => e.name)"
        )
        check(all(e.startswith(origin + "/") for e in entries), "the page's resource entries are all same-origin")
        errors = console_errors(driver)
        check(not errors, f"no console errors {errors}")
        print("all playground checks passed")
    finally:
        if driver is not None:
            driver.quit()
        server.terminate()
        try:
            server.wait(timeout=15)
        except subprocess.TimeoutExpired:
            server.kill()


if __name__ == "__main__":
    main()
