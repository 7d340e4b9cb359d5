"""inspect.lcm_spy: tools/lcm-spy's command (our types in a jar built with lcm-gen --java and
javac) starts LCM's spy under Xvfb; while NIGEL1_ODOM (odometry_t) and SIM_CLOCK (sim_clock_t)
are published on the test's own port, a screenshot of the spy's window, read with tesseract,
shows the channels with their type names: decoded, not "?"."""

from __future__ import annotations

import os
import pathlib
import shutil
import subprocess
import tempfile
import time

import mss
import mss.tools
from PIL import Image

from autodrive.core import lcmtypes
from autodrive.core.channels import channel
from autodrive.devtools.inspect import lcm_spy


def test_spy_decodes_our_channels(build_dir: pathlib.Path, lcm_port: int) -> None:
    build, port = build_dir, lcm_port
    url = f"udpm://239.255.76.67:{port}?ttl=0"
    DISPLAY, WAIT_S = f":{port % 1000 + 100}", 40.0
    types = lcmtypes.load(build)
    bus = lcmtypes.bus(url)

    def publish(k: int) -> None:
        odom = types.odometry_t()
        odom.utime, odom.vehicle, odom.frame_id, odom.child_frame_id = (
            k * 20000,
            "NIGEL1",
            "odom",
            "b",
        )
        odom.x_m = 0.01 * k
        bus.publish(channel("ODOM", "NIGEL1"), odom.encode())
        clock = types.sim_clock_t()
        clock.utime = k * 20000
        bus.publish(channel("SIM_CLOCK"), clock.encode())

    # Each channel with its type name: the spy shows "?" for a type it cannot decode. OCR drops
    # underscores now and then, so both sides are compared without them and without spaces.
    WANT = ("NIGEL1ODOModometryt", "SIMCLOCKsimclockt")

    def squeeze(text: str) -> str:
        return text.replace(" ", "").replace("_", "")

    def read_screen(path: pathlib.Path) -> str:
        with mss.mss(display=DISPLAY) as screen:
            shot = screen.grab(screen.monitors[1])
            mss.tools.to_png(shot.rgb, shot.size, output=str(path))
        # The window only (the root around it is black), grey and 3x larger: tesseract reads the
        # spy's small table font reliably at that size.
        image = Image.open(path).convert("L")
        window = image.point(lambda v: 255 if v > 0 else 0).getbbox()
        if window:
            image = image.crop(window)
        big = path.with_name("ocr.png")
        image.resize((image.width * 3, image.height * 3), Image.LANCZOS).save(big)
        r = subprocess.run(["tesseract", str(big), "stdout"], capture_output=True, text=True)
        return r.stdout

    with tempfile.TemporaryDirectory(prefix="lcm-spy-") as tmp:
        xvfb = subprocess.Popen(
            ["Xvfb", DISPLAY, "-screen", "0", "1280x800x24", "-nolisten", "tcp"]
        )
        spy = None
        try:
            time.sleep(1.0)
            env = dict(os.environ, DISPLAY=DISPLAY)
            spy = subprocess.Popen(
                lcm_spy.spy_command(build, url),
                env=env,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.PIPE,
                text=True,
            )
            text, shot, k = "", pathlib.Path(tmp) / "spy.png", 0
            deadline = time.time() + WAIT_S
            while time.time() < deadline:
                for _ in range(25):  # 0.5 s of messages at 50 Hz
                    publish(k)
                    k += 1
                    time.sleep(0.02)
                assert (
                    spy.poll() is None
                ), f"the spy exited: {spy.stderr.read() if spy.stderr else ''}"
                text = read_screen(shot)
                if all(w in squeeze(text) for w in WANT):
                    break
            keep = pathlib.Path(os.environ.get("LCM_SPY_SHOT", build / "lcm_spy.png"))
            shutil.copy(shot, keep)
            print(f"screenshot: {keep}\nOCR:\n{text}")
            missing = [w for w in WANT if w not in squeeze(text)]
            assert (
                not missing
            ), f"not shown (channel and decoded type, OCR without _ and spaces): {missing}"
        finally:
            for p in (spy, xvfb):
                if p is not None:
                    p.terminate()
                    p.wait(timeout=10)
    print("lcm-spy ok")
