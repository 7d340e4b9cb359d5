// A session's instance (two users on one machine), read in this one place for C++: the
// environment variable AUTODRIVE_INSTANCE=N (0..AUTODRIVE_INSTANCE_MAX; unset: 0). Instance N > 0
// moves every LCM URL on the default port to that port + N * AUTODRIVE_INSTANCE_PORT_STEP and
// the simulator's run dir (its ptys) to <run dir>-N; the rule is lcm_types/channels.yaml's
// `instances` (Python: autodrive.core.settings.instance(); the simulator: sim_instance.c).
#pragma once

#include <cstdlib>
#include <string>

#include <autodrive/strict_yaml.hpp>
#include <autodrive_channels.h>
#include <autodrive_instance_rule.h>

namespace autodrive {

// AUTODRIVE_INSTANCE holds no instance number; the message names the variable and the range.
struct InstanceError : InputError {
  using InputError::InputError;
};

class Instance {
 public:
  explicit Instance(int number) : number_(number) {}

  int number() const { return number_; }

  // url moved to this instance when it is a udpm:// URL on the default port; "" (LCM's own
  // default) becomes the moved default URL. Other ports and providers are the caller's choice.
  std::string lcm_url(const std::string &url) const {
    if (number_ == 0) return url;
    const std::string scheme = "udpm://";
    const std::string u = url.empty() ? std::string(AUTODRIVE_LCM_URL_DEFAULT) : url;
    if (u.compare(0, scheme.size(), scheme) != 0) return u;
    const std::size_t host_end = u.find_first_of(":?", scheme.size());
    std::size_t rest = host_end;
    int port = default_lcm_port();
    if (host_end != std::string::npos && u[host_end] == ':') {
      rest = u.find('?', host_end);
      port = std::atoi(u.substr(host_end + 1, rest - host_end - 1).c_str());
    }
    if (port != default_lcm_port()) return u;
    return u.substr(0, host_end) + ":" +
           std::to_string(port + number_ * AUTODRIVE_INSTANCE_PORT_STEP) +
           (rest == std::string::npos ? "" : u.substr(rest));
  }

  // A path in the simulator's default run dir, moved to this instance's run dir.
  std::string sim_path(const std::string &path) const {
    const std::string dir = AUTODRIVE_SIM_RUN_DIR_DEFAULT "/";
    if (number_ == 0 || path.compare(0, dir.size(), dir) != 0) return path;
    return AUTODRIVE_SIM_RUN_DIR_DEFAULT "-" + std::to_string(number_) + "/" +
           path.substr(dir.size());
  }

  // The port of AUTODRIVE_LCM_URL_DEFAULT ("udpm://239.255.76.67:7667?ttl=0" -> 7667).
  static int default_lcm_port() {
    const std::string d = AUTODRIVE_LCM_URL_DEFAULT;
    const std::size_t colon = d.rfind(':');
    return std::atoi(d.c_str() + colon + 1);
  }

 private:
  int number_;
};

// The session's instance, from AUTODRIVE_INSTANCE; throws InstanceError on a bad value.
inline Instance instance() {
  const char *v = std::getenv(AUTODRIVE_INSTANCE_VARIABLE);
  if (!v || !*v) return Instance(0);
  char *end = nullptr;
  const long n = std::strtol(v, &end, 10);
  if (*end || n < 0 || n > AUTODRIVE_INSTANCE_MAX)
    throw InstanceError(std::string(AUTODRIVE_INSTANCE_VARIABLE) + "='" + v +
                        "': expected an instance number in 0.." +
                        std::to_string(AUTODRIVE_INSTANCE_MAX) + " (0, or unset, is the default)");
  return Instance(static_cast<int>(n));
}

// url moved to the session's instance (the form every config reader and CLI uses).
inline std::string instance_lcm_url(const std::string &url) {
  return instance().lcm_url(url);
}

}  // namespace autodrive
