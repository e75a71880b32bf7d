#!/usr/bin/python3
"""The live preview in a real browser (DESIGN.md §14): headless Chromium, driven through WebDriver,
opens the page while glint renders and checks that tiles appear during the render, that the final
canvas equals the written PNG pixel for pixel, and that the page survives the end of the render, a
reload, and glint's stopping after Ctrl-C.

    preview_browser_test.py GLINT SCENE WORK_DIR

Exit status 0 pass, 1 fail, 77 skipped: Chromium, chromedriver or Selenium missing (Debian's
chromium, chromium-driver, python3-selenium; scripts/setup.sh test installs them) — but under CI
(CI=true) a missing browser is a failure, so the test cannot silently vanish there.
"""
import os
import re
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
import zlib

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
CHROMEDRIVER = shutil.which("chromedriver") or "/usr/bin/chromedriver"
# What works as root in a container, and keeps Chromium off the network.
CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync",
                  "--disable-dev-shm-usage", "--window-size=1200,900"]
# The rendered image: small enough to read back quickly, slow enough (several seconds at one
# thread) that the page sees it while it renders.
RENDER_OPTIONS = ["--width", "320", "--threads", "1"]


def fail(message):
    print("FAIL: " + message, flush=True)
    sys.exit(1)


def skip_or_fail(message):
    if os.environ.get("CI", "").lower() in ("1", "true", "yes"):
        fail(message + " (required under CI)")
    print("SKIPPED: " + message, flush=True)
    sys.exit(77)


def read_png_rgb(path):
    """Width, height and RGB bytes of an 8-bit, non-interlaced RGB or RGBA PNG (what glint writes)."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        fail(path + " is not a PNG")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, color, _, _, interlace = header
    if depth != 8 or color not in (2, 6) or interlace != 0:
        fail("unexpected PNG format in " + path)
    channels = 3 if color == 2 else 4
    raw, stride = zlib.decompress(idat), width * channels
    rows, previous = [], bytearray(stride)
    for y in range(height):
        kind, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            left = line[i - channels] if i >= channels else 0
            up, corner = previous[i], previous[i - channels] if i >= channels else 0
            if kind == 1:
                line[i] = (line[i] + left) & 255
            elif kind == 2:
                line[i] = (line[i] + up) & 255
            elif kind == 3:
                line[i] = (line[i] + (left + up) // 2) & 255
            elif kind == 4:
                p = left + up - corner
                pa, pb, pc = abs(p - left), abs(p - up), abs(p - corner)
                line[i] = (line[i] + (left if pa <= pb and pa <= pc else up if pb <= pc else corner)) & 255
        rows.append(bytes(line))
        previous = line
    rgb = b"".join(rows)
    if channels == 4:
        rgb = bytes(b for i, b in enumerate(rgb) if i % 4 != 3)
    return width, height, rgb


CANVAS_RGB = """
const canvas = document.getElementById('image');
if (canvas.width === 0) return null;
const rgba = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data;
const parts = [];
for (let i = 0; i < rgba.length; i += 4) parts.push(String.fromCharCode(rgba[i], rgba[i + 1], rgba[i + 2]));
return [canvas.width, canvas.height, btoa(parts.join(''))];
"""


def wait_for(what, condition, timeout):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = condition()
        if value:
            return value
        time.sleep(0.05)
    fail("timed out after %g s waiting for %s" % (timeout, what))


def compare_canvas(driver, png, when):
    import base64
    shown = driver.execute_script(CANVAS_RGB)
    if shown is None:
        fail(when + ": the canvas is empty")
    width, height, rgb = shown[0], shown[1], base64.b64decode(shown[2])
    if (width, height) != png[:2]:
        fail("%s: the canvas is %dx%d, the PNG %dx%d" % (when, width, height, png[0], png[1]))
    if rgb != png[2]:
        differing = sum(1 for i in range(0, len(rgb), 3) if rgb[i:i + 3] != png[2][i:i + 3])
        fail("%s: %d of %d canvas pixels differ from the PNG" % (when, differing, width * height))
    print("ok: %s: the canvas equals the PNG (%dx%d)" % (when, width, height), flush=True)


def main():
    if len(sys.argv) != 4:
        print(__doc__)
        return 2
    glint, scene, work = sys.argv[1], sys.argv[2], sys.argv[3]
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
    except ImportError:
        skip_or_fail("python3-selenium is not installed")
    for program in (CHROMIUM, CHROMEDRIVER):
        if not os.access(program, os.X_OK):
            skip_or_fail(program + " is not installed")

    os.makedirs(work, exist_ok=True)
    output = os.path.join(work, "preview.png")
    if os.path.exists(output):
        os.remove(output)
    profile = tempfile.mkdtemp(prefix="glint-chromium-")
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in CHROMIUM_FLAGS + ["--user-data-dir=" + profile]:
        options.add_argument(flag)
    # The browser first: it takes longer to start than the page takes to load.
    driver = webdriver.Chrome(service=Service(executable_path=CHROMEDRIVER), options=options)
    driver.set_page_load_timeout(20)
    glint_log = open(os.path.join(work, "glint.log"), "w+")
    process = subprocess.Popen([glint, "render", scene, "-o", output, "--preview", "0",
                                "--preview-linger", "120"] + RENDER_OPTIONS,
                               stdout=subprocess.DEVNULL, stderr=glint_log)
    try:
        def log():
            glint_log.seek(0)
            return glint_log.read()

        url = wait_for("glint's preview address",
                       lambda: (re.search(r"preview at (http://127\.0\.0\.1:\d+/)", log()) or [None, None])[1], 20)
        driver.get(url)
        state = lambda: driver.execute_script("return window.glintPreview")

        # 1. Tiles appear while the render runs.
        during = wait_for("tiles during the render", lambda: (lambda s: s if s and s["phase"] == "rendering"
                          and s["tilesWhileRendering"] > 0 else None)(state()), 60)
        status = during["status"]
        if status["tilesDone"] >= status["tilesTotal"]:
            fail("the render was over before the page saw it; make it slower")
        print("ok: %d blocks shown while rendering (%d of %d tiles done)"
              % (during["tilesWhileRendering"], status["tilesDone"], status["tilesTotal"]), flush=True)
        driver.save_screenshot(os.path.join(work, "during-render.png"))

        # 2. The finished picture is the written PNG, with the summary beside it.
        final = wait_for("the finished render", lambda: (lambda s: s if s and s["phase"] == "finished" else None)(state()), 120)
        wait_for("the PNG", lambda: "the preview stays at" in log(), 30)
        png = read_png_rgb(output)
        compare_canvas(driver, png, "after the render")
        if "glint: wrote " not in final["status"]["summary"]:
            fail("no summary on the page: " + repr(final["status"]["summary"]))
        if "ETA" in driver.find_element("id", "numbers").text:
            fail("an ETA is still shown after the render")
        driver.save_screenshot(os.path.join(work, "finished.png"))

        # 3. A reload after the render gets the whole picture and the summary again.
        driver.refresh()
        again = wait_for("the page after a reload",
                         lambda: (lambda s: s if s and s["phase"] == "finished" else None)(state()), 30)
        if again["tilesWhileRendering"] != 0 or again["tilesReceived"] == 0:
            fail("after the reload: unexpected tiles " + repr(again))
        compare_canvas(driver, png, "after a reload")

        # 4. Ctrl-C ends serving (exit 0: the render succeeded); the page keeps the picture.
        process.send_signal(signal.SIGINT)
        status = process.wait(timeout=15)
        if status != 0:
            fail("glint exited with %d after Ctrl-C; its log:\n%s" % (status, log()))
        wait_for("the page to notice glint stopped", lambda: state()["closed"], 15)
        compare_canvas(driver, png, "after glint stopped serving")
        print("ok: the page survives the end of the render, a reload and glint stopping", flush=True)
        return 0
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
        driver.quit()
        shutil.rmtree(profile, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
