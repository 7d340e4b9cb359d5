"""The SCM's web app in a real browser (Debian's Chromium through chromedriver, Selenium),
against autodrive-sim on Tiny Town (3 cars, its traffic lights on real LCM) and three cars'
EKF poses published here along the loop routes. An operator logs in, sees the three cars move
in the vehicle table and on the map, puts the junction in manual, clicks light 1 on the map
to GREEN and again to RED, and the simulator's TRAFFIC_LIGHT_STATE follows (YELLOW, then RED);
a viewer logs in, clicks light 1 and is refused (403 naming the role, shown on the page) and
the simulator's light stays RED. Screenshots: out/scm/browser_operator.png,
out/scm/browser_viewer.png. Args: ROOT BUILD PORT."""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from harness import (
    CarFeeder,
    LightWatch,
    Server,
    add_user,
    check,
    chromium,
    click_light,
    start_sim,
    wait_for,
)
from harness import login_page as login
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select, WebDriverWait

from autodrive.core import lcmtypes, v2x_auth, v2x_ca
from autodrive.core.channels import channel


def test_lights_from_the_browser(root: Path, build_dir: Path, lcm_port: int, lcm_url: str) -> None:
    build, port = str(build_dir), lcm_port
    url = lcm_url
    T = lcmtypes.load(build)
    S = T.traffic_light_state_t
    out = root / "out" / "scm"
    out.mkdir(parents=True, exist_ok=True)
    lc = lcmtypes.bus(url)
    feed_lc = lcmtypes.bus(url)

    def table(driver) -> dict[str, tuple[float, float, str]]:  # type: ignore[no-untyped-def]
        """The vehicle table as the page shows it (read in one script: it is redrawn at 10 Hz)."""
        rows = {}
        texts = driver.execute_script(
            "return [...document.querySelectorAll('#vehicles tbody tr')]"
            ".map(tr => [...tr.cells].map(td => td.textContent));"
        )
        for cells in texts:
            if len(cells) >= 6 and cells[1]:
                rows[cells[0]] = (float(cells[1]), float(cells[2]), cells[5])
        return rows

    with tempfile.TemporaryDirectory(prefix="scm-browser-") as tmp:
        db = f"sqlite:///{tmp}/scm.sqlite"
        add_user(db, "op1", "operator", "operator-pass")
        add_user(db, "viewer1", "viewer", "viewer-pass")
        sim = start_sim(build, url, tmp)
        bus_clock = v2x_auth.BusClock()  # the sim's time, for the probe's signature
        lc.subscribe(
            channel("TRAFFIC_LIGHT_STATE"),
            lambda _c, d: bus_clock.heard(T.traffic_light_state_t.decode(d).utime),
        )
        watch = LightWatch(lc, T)
        feeder = CarFeeder(feed_lc, T, {"NIGEL1": ("loop_ccw", 0.5), "NIGEL2": ("loop_ccw", 8.0),
                                        "NIGEL3": ("loop_cw", 3.0)}, 0.4)  # fmt: skip
        srv = Server(db, url, build, "NIGEL1,NIGEL2,NIGEL3,NIGEL4")  # NIGEL4 never drives
        driver = chromium()
        try:
            wait_for(
                lambda: watch.latest(1) is not None, 30, "the simulator publishes light states"
            )
            driver.get(srv.url + "/")
            WebDriverWait(driver, 20).until(lambda d: d.find_element(By.ID, "login-name"))
            check(
                not driver.find_element(By.ID, "map").is_displayed()
                and not driver.find_element(By.ID, "vehicles").is_displayed(),
                "before login: the login form only, no map and no tables",
            )
            driver.save_screenshot(str(out / "browser_login.png"))
            login(driver, srv.url, "op1", "operator-pass")
            WebDriverWait(driver, 20).until(lambda d: len(table(d)) == 3)
            ghost = driver.execute_script(
                "const tr = document.querySelector('#vehicles tr[data-name=NIGEL4]');"
                "return tr ? tr.textContent : null;"
            )
            check(ghost == "NIGEL4not seen yet", f"a car never seen is not put at 0, 0: {ghost}")
            unlabelled = driver.execute_script(
                "return [...document.querySelectorAll('input.prog')].filter(i => "
                "!document.querySelector(`label[for='${i.id}']`)).map(i => i.id);"
            )
            check(not unlabelled, f"every program input has its label: {unlabelled}")
            junction = driver.find_element(By.ID, "junctions").text
            check("cross tile at" in junction, f"the junction named as the map has it: {junction}")
            first = table(driver)
            time.sleep(1.5)
            second = table(driver)
            moved = {
                n: abs(second[n][0] - first[n][0]) + abs(second[n][1] - first[n][1]) for n in first
            }
            check(
                sorted(first) == ["NIGEL1", "NIGEL2", "NIGEL3"],
                f"three cars in the table: {sorted(first)}",
            )
            check(all(d > 0.2 for d in moved.values()), f"each car moved > 0.2 m in 1.5 s: {moved}")
            check(all(second[n][2] == "ok" for n in second), "each car's status is ok")
            Select(driver.find_element(By.ID, "mode-x")).select_by_visible_text("manual")
            for other in (2, 4):  # the lights conflicting with light 1 to red
                driver.find_element(By.ID, f"light-{other}-red").click()
            wait_for(lambda: watch.latest(2) == S.RED and watch.latest(4) == S.RED, 10,
                     "lights 2 and 4 RED in the simulator")  # fmt: skip
            time.sleep(1.2)  # all-red
            if watch.latest(1) != S.GREEN:
                click_light(driver, 1)
                wait_for(
                    lambda: watch.latest(1) == S.GREEN,
                    10,
                    "click on light 1: GREEN in the simulator",
                )
            driver.save_screenshot(str(out / "browser_operator_green.png"))
            # the simulator itself refuses a conflicting green sent past the SCM (signed as the
            # SCM: an unsigned one it drops before its interlock sees it)
            probe = T.traffic_light_command_t()
            probe.utime, probe.light_id, probe.state, probe.duration_s = 0, 2, S.GREEN, 1.0
            scm_signer = v2x_auth.MessageSigner(v2x_ca.load_identity("SCM"))
            scm_signer.sign(channel("TRAFFIC_LIGHT_COMMAND"), probe, bus_clock.now_us())
            t_probe = time.time()
            lc.publish(channel("TRAFFIC_LIGHT_COMMAND"), probe.encode())
            # the light's next states (event order; the wait is a hang guard, not a deadline)
            wait_for(lambda: sum(i == 2 for t, i, _ in watch.states if t > t_probe) >= 3, 60,
                     "light 2's states after the probe")  # fmt: skip
            l2 = [s for t, i, s in watch.states if t > t_probe and i == 2]
            check(bool(l2) and all(s == S.RED for s in l2), "the simulator refused light 2 GREEN")
            t_click = time.time()
            click_light(driver, 1)
            wait_for(lambda: watch.first_after(1, S.YELLOW, t_click) is not None, 60,
                     "click on green light 1: YELLOW in the simulator")  # fmt: skip
            wait_for(lambda: watch.first_after(1, S.RED, t_click) is not None, 60,
                     "then RED in the simulator")  # fmt: skip
            # on the simulator's clock (the lights' own stamps), not the wall time of receipt
            ty = watch.first_sim_s_after(1, S.YELLOW, t_click)
            tr = watch.first_sim_s_after(1, S.RED, t_click)
            assert ty is not None and tr is not None
            check(
                1.8 <= tr - ty <= 2.6, f"yellow lasted {tr - ty:.2f} s of sim time (2 s, enforced)"
            )
            time.sleep(0.5)
            driver.save_screenshot(str(out / "browser_operator.png"))
            log = driver.find_element(By.ID, "events").text
            check("op1 light_request light 1" in log, "the event log names op1's request")
            check(
                log.index("Operators' actions")
                < log.index("op1 light_request")
                < log.index("Programmed changes")
                and "{" not in log.split("Programmed")[1],
                "operators' actions first, then the programmed changes, grouped, no raw JSON",
            )

            driver.delete_all_cookies()
            login(driver, srv.url, "viewer1", "viewer-pass")
            WebDriverWait(driver, 20).until(lambda d: len(table(d)) == 3)
            check(
                not driver.find_element(By.ID, "light-1-green").is_enabled(),
                "viewer: buttons disabled",
            )
            t_click = time.time()
            click_light(driver, 1)
            WebDriverWait(driver, 10).until(
                lambda d: "403" in d.find_element(By.ID, "message").text
            )
            msg = driver.find_element(By.ID, "message").text
            check("operator role required" in msg, f"viewer's click refused on the page: {msg}")
            time.sleep(1.5)
            later = [s for t, i, s in watch.states if t > t_click and i == 1]
            check(
                bool(later) and all(s == S.RED for s in later), "the simulator's light 1 stayed RED"
            )
            driver.save_screenshot(str(out / "browser_viewer.png"))
        finally:
            driver.quit()
            feeder.stop()
            watch.stop()
            rc = srv.stop()
            sim.terminate()
            _, err = sim.communicate(timeout=20)
        refused = [ln for ln in err.splitlines() if "refused" in ln]
        check(
            len(refused) == 1 and "light 2" in refused[0] and "light 1" in refused[0],
            f"the simulator logged one refusal, the probe's, naming lights 2 and 1: {refused}",
        )
        check(rc == 0, "server stopped cleanly")
    print("OK")
