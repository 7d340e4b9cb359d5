// The autodrive-sim program: lockstep determinism (same seed -> identical ground-truth log
// bytes), clear errors for bad parameter and map files, --help.
#include <gtest/gtest.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <sstream>
#include <string>

#include "sim_test_util.h"

namespace {

struct ProcResult {
  int status;
  std::string out;
};

ProcResult run(const std::string &args) {
  const std::string cmd = std::string(SIM_BIN) + " " + args + " 2>&1";
  ProcResult r{-1, ""};
  FILE *p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[512];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

std::string slurp(const std::string &path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

TEST(Cli, HelpListsTheOptions) {
  const ProcResult r = run("--help");
  EXPECT_EQ(r.status, 0);
  for (const char *opt : {"--cars", "--map", "--lockstep", "--rtf", "--seed", "--duration",
                          "--lcm-url", "--script", "--run-dir"})
    EXPECT_NE(r.out.find(opt), std::string::npos) << opt;
}

TEST(Cli, LockstepIsDeterministicForASeed) {
  const std::string dir = simtest::temp_dir();
  const std::string common =
      " --lockstep --duration 3 --cars 2 --no-pty --quiet --lcm-url memq:// "
      "--script constant:throttle=0.7,steering=0.4 --run-dir " +
      dir;
  const ProcResult a = run("--seed 7 --truth-log " + dir + "/a.bin" + common);
  ASSERT_EQ(a.status, 0) << a.out;
  const ProcResult b = run("--seed 7 --truth-log " + dir + "/b.bin" + common);
  ASSERT_EQ(b.status, 0) << b.out;
  const std::string la = slurp(dir + "/a.bin"), lb = slurp(dir + "/b.bin");
  // 2 cars x 100 Hz x 3 s messages, each with a 4-byte length prefix
  EXPECT_GT(la.size(), 600u * 100u);
  EXPECT_TRUE(la == lb) << "ground-truth logs differ";
  // the run really moved the cars: the last record differs from the first
  EXPECT_NE(la.substr(4, 100), la.substr(la.size() - 100));
  unlink((dir + "/a.bin").c_str());
  unlink((dir + "/b.bin").c_str());
  rmdir(dir.c_str());
}

TEST(Cli, BadParameterFileIsRejectedNamingFileAndKey) {
  const std::string dir = simtest::temp_dir(), path = dir + "/broken.params";
  std::string text = slurp(simtest::params_path());
  text.replace(text.find("wheel_radius_m = 0.0325"), 23, "wheel_radius_m = 3.25cm");
  std::ofstream(path) << text;
  const ProcResult r = run("--lockstep --duration 0.1 --no-pty --lcm-url memq:// --run-dir " + dir +
                           " --params " + path);
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("broken.params"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("wheel_radius_m"), std::string::npos) << r.out;
  unlink(path.c_str());
  rmdir(dir.c_str());
}

TEST(Cli, BadMapFileIsRejectedNamingTheMap) {
  const std::string dir = simtest::temp_dir();
  ProcResult r = run("--lockstep --duration 0.1 --no-pty --lcm-url memq:// --run-dir " + dir +
                     " --map " + simtest::fixture("broken_map.xml"));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("broken_map.xml"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("colour"), std::string::npos) << r.out;
  r = run("--lockstep --duration 0.1 --no-pty --lcm-url memq:// --run-dir " + dir +
          " --map no_such_map");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("no_such_map"), std::string::npos) << r.out;
  EXPECT_EQ(rmdir(dir.c_str()), 0) << "a failed start left files in the run dir";
}

TEST(Cli, BadOptionsAreRejected) {
  EXPECT_EQ(run("--cars 0").status, 2);
  EXPECT_EQ(run("--rtf fast").status, 2);
  EXPECT_EQ(run("--lockstep --rtf 3").status, 2);
  EXPECT_EQ(run("--frobnicate").status, 2);
  // the window's look: named errors, and each needs --view
  for (const char *bad : {"--view --view-scale 2", "--view --view-quality best",
                          "--view --view-nice 2.5", "--view-scale 0.5", "--view-nice 5"}) {
    const ProcResult v = run(bad);
    EXPECT_EQ(v.status, 2) << bad;
    EXPECT_NE(v.out.find("--view"), std::string::npos) << bad << ": " << v.out;
  }
  for (const char *bad : {"--camera-scale 0.1", "--camera-scale 2", "--camera-scale half"}) {
    const ProcResult v = run(bad);
    EXPECT_EQ(v.status, 2) << bad;
    EXPECT_NE(v.out.find("--camera-scale"), std::string::npos) << bad << ": " << v.out;
  }
  const ProcResult r = run("--lockstep --no-pty --lcm-url memq:// --script constant:throttle=9");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("throttle"), std::string::npos) << r.out;
}

// Domain randomisation (issue 38): bad values name the option and the value, exit 2.
TEST(Cli, RandomisationBoundsAreRefusedNamingOptionAndValue) {
  for (const char *bad :
       {"--light-rgb 1.6,1,1", "--light-rgb 1,0.4,1", "--light-rgb 1,1", "--light-rgb 1,1,1,1",
        "--light-rgb red", "--camera-exposure 2.5", "--camera-exposure -3", "--camera-exposure x",
        "--camera-jitter 11,1", "--camera-jitter 5,3.5", "--camera-jitter -1,1",
        "--camera-jitter 5", "--distractors 21", "--distractors -1", "--distractors 2.5"}) {
    const ProcResult r = run(bad);
    EXPECT_EQ(r.status, 2) << bad << ": " << r.out;
    const std::string opt(bad, strchr(bad, ' ')), value(strchr(bad, ' ') + 1);
    EXPECT_NE(r.out.find(opt + " '" + value + "'"), std::string::npos) << bad << ": " << r.out;
  }
  const ProcResult h = run("--help");
  for (const char *opt :
       {"--light-rgb R,G,B", "--camera-exposure EV", "--camera-jitter MM,DEG", "--distractors N"})
    EXPECT_NE(h.out.find(opt), std::string::npos) << opt;
}

// --camera-jitter prints each car's drawn offset once: the same for a seed, another for
// another seed or car; with the other options the run starts and ends cleanly.
TEST(Cli, CameraJitterIsPrintedOncePerCarFromTheSeed) {
  const std::string dir = simtest::temp_dir();
  const std::string common =
      " --lockstep --duration 0.1 --cars 2 --no-pty --no-lidar --lcm-url memq:// --run-dir " + dir +
      " --camera-jitter 10,3 --light-rgb 1.2,0.9,0.7 --light-level 0.8 --camera-exposure -1"
      " --distractors 5 --map tiny_town";
  const ProcResult a = run("--seed 1" + common), b = run("--seed 1" + common),
                   c = run("--seed 2" + common);
  ASSERT_EQ(a.status, 0) << a.out;
  ASSERT_EQ(c.status, 0) << c.out;
  auto lines = [](const std::string &out, const char *car) {
    std::string found;
    int n = 0;
    for (size_t at = 0;
         (at = out.find(std::string(car) + " cam_front jitter", at)) != std::string::npos;
         at++, n++)
      found = out.substr(at, out.find('\n', at) - at);
    return n == 1 ? found : std::string("printed ") + std::to_string(n) + " times";
  };
  const std::string a1 = lines(a.out, "NIGEL1"), a2 = lines(a.out, "NIGEL2");
  EXPECT_NE(a1.find(" mm; "), std::string::npos) << a1;
  EXPECT_EQ(a1, lines(b.out, "NIGEL1"));
  EXPECT_NE(a1, lines(c.out, "NIGEL1"));
  EXPECT_NE(a1.substr(6), a2.substr(6)) << "each car draws its own";
  EXPECT_EQ(rmdir(dir.c_str()), 0);
}

TEST(Cli, PtySymlinksArePrintedAndRemovedOnExit) {
  const std::string dir = simtest::temp_dir();
  const ProcResult r =
      run("--lockstep --duration 0.2 --cars 2 --no-lidar --lcm-url memq:// --run-dir " + dir);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find(dir + "/nigel1-nano"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(dir + "/nigel2-nano"), std::string::npos) << r.out;
  EXPECT_NE(access((dir + "/nigel1-nano").c_str(), F_OK), 0);  // removed at exit
  EXPECT_EQ(rmdir(dir.c_str()), 0) << "run dir not left empty";
}

TEST(Cli, SigtermShutsDownCleanly) {
  for (int sig : {SIGTERM, SIGINT}) {
    const std::string dir = simtest::temp_dir(), link = dir + "/nigel1-nano";
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {  // real-time run without an end: only the signal stops it
      if (!freopen("/dev/null", "w", stdout)) _exit(126);
      execl(SIM_BIN, SIM_BIN, "--quiet", "--no-lidar", "--lcm-url", "memq://", "--run-dir",
            dir.c_str(), (char *)nullptr);
      _exit(127);
    }
    // wait (not a timing assertion) until the sim is up and its symlink exists
    for (int i = 0; i < 600 && access(link.c_str(), F_OK) != 0; i++) usleep(50000);
    ASSERT_EQ(access(link.c_str(), F_OK), 0) << "sim never created " << link;
    kill(pid, sig);
    int st = 0;
    ASSERT_EQ(waitpid(pid, &st, 0), pid);
    EXPECT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0) << "signal " << sig << " status " << st;
    EXPECT_NE(access(link.c_str(), F_OK), 0) << "symlink left behind";
    EXPECT_EQ(rmdir(dir.c_str()), 0) << "run dir not left empty (scene or links remain)";
  }
}

}  // namespace
