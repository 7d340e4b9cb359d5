// Signed commands: the one C++ signer and verifier of <VEH>_COMMAND (autodrive::vehicle_command_t).
// Modelled on MAVLink 2 message signing: every command names its source, carries a strictly
// increasing counter (the sender's wall clock [us]) and a truncated HMAC-SHA-256 over canonical
// bytes with the car's 32-byte key. The canonical byte order is documented once, in
// lcm_types/autodrive/vehicle_command_t.lcm; tests/foundation/command_auth_vectors.json holds
// vectors the Python signer (autodrive.core.command_auth) must match byte for byte.
#pragma once

#include <autodrive/strict_yaml.hpp>
#include <autodrive/vehicle_command_t.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace autodrive::auth {

constexpr size_t kKeyBytes = 32;
constexpr size_t kMacBytes = 16;
constexpr size_t kMaxSourceChars = 32;
// vehicle_command_t's AUTHORITY_* as constants that may be bound to references (LCM's in-class
// constants have no definition to link against).
constexpr int8_t kAuthorityMachine = autodrive::vehicle_command_t::AUTHORITY_MACHINE;
constexpr int8_t kAuthorityPerson = autodrive::vehicle_command_t::AUTHORITY_PERSON;
using Key = std::array<uint8_t, kKeyBytes>;
using Mac = std::array<uint8_t, kMacBytes>;

// Where a car's key lives unless a config names a file: $AUTODRIVE_KEY_DIR/<VEH>.key, else
// $XDG_CONFIG_HOME/autodrive/keys/<VEH>.key, else ~/.config/autodrive/keys/<VEH>.key.
std::string default_key_path(const std::string &vehicle);

// Reads a key file (64 hex digits, one line; written by tools/keys). Throws InputError naming
// the file when it is missing, readable by group or others (it must be mode 0600 or 0400), or
// not 64 hex digits.
Key load_key(const std::string &path);

// The canonical bytes M of a command for `vehicle` (see vehicle_command_t.lcm).
std::vector<uint8_t> canonical_bytes(const autodrive::vehicle_command_t &c,
                                     const std::string &vehicle);
// HMAC-SHA-256(key, M) truncated to kMacBytes.
Mac mac_of(const Key &key, const std::vector<uint8_t> &m);

// "" when the source id is usable, else what is wrong with it.
std::string source_problem(const std::string &source);

// Fills source, authority, counter and mac of commands for one car.
class Signer {
 public:
  // Throws InputError on a bad source id or authority.
  Signer(const Key &key, std::string vehicle, std::string source, int8_t authority);
  // Sets c.source, c.authority, c.counter (wall clock [us], at least last + 1) and c.mac.
  void sign(autodrive::vehicle_command_t &c);
  const std::string &source() const { return source_; }

 private:
  Key key_;
  std::string vehicle_, source_;
  int8_t authority_;
  int64_t last_counter_ = 0;
};

// For a program's main: the signer with which `source` commands `vehicle` as a machine, its key
// from key_file or, when that is "", from default_key_path(vehicle). On a bad key or source it
// prints "<program>: --key-file: <why>" to stderr and returns nullopt (the caller exits 2).
std::optional<Signer> load_machine_signer(const char *program, const std::string &vehicle,
                                          const std::string &key_file, const std::string &source);

enum class MacCheck { ok, unsigned_cmd, bad_mac };
// Whether c carries a signature at all and whether it is valid for key (constant-time compare).
MacCheck check_mac(const Key &key, const std::string &vehicle,
                   const autodrive::vehicle_command_t &c);

}  // namespace autodrive::auth
