"""ProcessGroup.stop_all (autodrive.core.proc) hands back every child's exit code and the
sanitizer report in its log, so a report at shutdown reaches the test or mission: real children,
among them a C program built here with -fsanitize=address,undefined that leaks at exit (LSan)
and one that overflows a signed int (UBSan); a clean child reports nothing."""

import shutil
import subprocess
import sys
import time

import pytest

from autodrive.core.proc import ProcessGroup, sanitizer_failures

LEAKS = r"""
#include <stdlib.h>
#include <stdio.h>
#include <signal.h>
#include <unistd.h>
static volatile sig_atomic_t stop;
static void on_int(int s) { (void)s; stop = 1; }
int main(int argc, char **argv) {
  signal(SIGINT, on_int);
  int x = argc > 1 ? atoi(argv[1]) : 0;
  char *p = malloc(64);  /* never freed: a leak LSan reports at exit */
  p[0] = (char)x;
  printf("ready %d\n", x + 2147483647);  /* argv 1: a signed overflow UBSan reports */
  fflush(stdout);
  while (!stop) usleep(10000);
  p = NULL;
  return 0;
}
"""


@pytest.fixture(scope="module")
def leaky(tmp_path_factory):
    if not shutil.which("gcc"):
        pytest.skip("gcc not installed")
    d = tmp_path_factory.mktemp("leaky")
    (d / "leaky.c").write_text(LEAKS)
    exe = d / "leaky"
    subprocess.run(["gcc", "-O0", "-g", "-fsanitize=address,undefined", str(d / "leaky.c"),
                    "-o", str(exe)], check=True)  # fmt: skip
    return exe


def run_group(tmp_path, children):
    procs = ProcessGroup(lambda m: None)
    for name, argv, env_opts in children:
        logfile = tmp_path / f"{name}.log"
        procs.start(name, ["env", env_opts, *argv], logfile)
    # every child prints one line when it is up: wait for it (event order, not a sleep), or for
    # its end (a child whose sanitizer halts it may end before the others are up)
    running = {name: proc for name, proc, _f in procs.items}
    for name, _argv, _env in children:
        logfile = tmp_path / f"{name}.log"
        while "ready" not in logfile.read_text() and running[name].poll() is None:
            time.sleep(0.01)
    return procs


def test_reports_and_exit_codes_reach_the_result(tmp_path, leaky):
    clean = [sys.executable, "-c", "import time; print('ready', flush=True); time.sleep(60)"]
    procs = run_group(tmp_path, [
        ("clean", clean, "ASAN_OPTIONS=detect_leaks=1"),
        ("leaks", [str(leaky), "0"], "ASAN_OPTIONS=detect_leaks=1"),
        ("overflows", [str(leaky), "1"], "ASAN_OPTIONS=detect_leaks=0"),
    ])  # fmt: skip
    exits = {e.name: e for e in procs.stop_all()}
    assert list(exits) == ["clean", "leaks", "overflows"]
    assert exits["clean"].sanitizer_report is None and not exits["clean"].killed
    assert "LeakSanitizer" in (exits["leaks"].sanitizer_report or ""), exits["leaks"]
    assert exits["leaks"].exit_code != 0  # LSan's exit code
    assert "runtime error" in (exits["overflows"].sanitizer_report or ""), exits["overflows"]
    bad = sanitizer_failures(list(exits.values()))
    assert len(bad) == 2 and bad[0].startswith("leaks: sanitizer report")


def test_stop_all_checked_raises_on_a_report(tmp_path, leaky):
    procs = run_group(tmp_path, [("leaks", [str(leaky), "0"], "ASAN_OPTIONS=detect_leaks=1")])
    with pytest.raises(RuntimeError, match="leaks: sanitizer report"):
        procs.stop_all_checked()
