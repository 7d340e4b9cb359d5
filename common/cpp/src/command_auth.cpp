#include <autodrive/command_auth.hpp>

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <sstream>

namespace autodrive::auth {

namespace {

void put_u8(std::vector<uint8_t> &m, uint8_t v) {
  m.push_back(v);
}
void put_be(std::vector<uint8_t> &m, uint64_t v, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) m.push_back(static_cast<uint8_t>(v >> (8 * i)));
}
void put_f32(std::vector<uint8_t> &m, float f) {
  uint32_t bits = 0;
  std::memcpy(&bits, &f, sizeof bits);
  put_be(m, bits, 4);
}
void put_str(std::vector<uint8_t> &m, const std::string &s) {
  put_u8(m, static_cast<uint8_t>(std::min<size_t>(s.size(), 255)));
  m.insert(m.end(), s.begin(), s.begin() + static_cast<long>(std::min<size_t>(s.size(), 255)));
}

int64_t wall_us() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

std::string default_key_path(const std::string &vehicle) {
  if (const char *d = std::getenv("AUTODRIVE_KEY_DIR"); d && *d)
    return std::string(d) + "/" + vehicle + ".key";
  std::string base;
  if (const char *x = std::getenv("XDG_CONFIG_HOME"); x && *x)
    base = x;
  else if (const char *h = std::getenv("HOME"); h && *h)
    base = std::string(h) + "/.config";
  else
    base = ".config";
  return base + "/autodrive/keys/" + vehicle + ".key";
}

Key load_key(const std::string &path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    throw InputError(path + ": command key file missing (create it with tools/keys create)");
  if ((st.st_mode & (S_IRWXG | S_IRWXO)) != 0)
    throw InputError(path + ": command key file is readable by group or others (mode " + [&] {
      std::ostringstream o;
      o << std::oct << (st.st_mode & 0777);
      return o.str();
    }() + "); chmod 600 it");
  std::ifstream f(path);
  std::string hex;
  if (!f || !(f >> hex)) throw InputError(path + ": command key file cannot be read");
  std::string rest;
  if (hex.size() != 2 * kKeyBytes || (f >> rest) ||
      !std::all_of(hex.begin(), hex.end(), [](char ch) { return std::isxdigit(ch) != 0; }))
    throw InputError(path + ": command key file must hold 64 hex digits (32 bytes) on one line");
  Key k{};
  for (size_t i = 0; i < kKeyBytes; ++i)
    k[i] = static_cast<uint8_t>(std::stoul(hex.substr(2 * i, 2), nullptr, 16));
  return k;
}

std::vector<uint8_t> canonical_bytes(const autodrive::vehicle_command_t &c,
                                     const std::string &vehicle) {
  std::vector<uint8_t> m;
  m.reserve(96);
  static const char kMagic[] = "ADCMD1";
  m.insert(m.end(), kMagic, kMagic + 6);
  put_str(m, vehicle);
  put_str(m, c.source);
  put_u8(m, static_cast<uint8_t>(c.authority));
  put_be(m, static_cast<uint64_t>(c.counter), 8);
  put_be(m, static_cast<uint64_t>(c.utime), 8);
  put_be(m, static_cast<uint32_t>(c.seq), 4);
  put_f32(m, c.throttle);
  put_f32(m, c.steering);
  put_u8(m, static_cast<uint8_t>(c.headlights));
  put_u8(m, static_cast<uint8_t>(c.indicators));
  put_u8(m, c.engaged ? 1 : 0);
  return m;
}

Mac mac_of(const Key &key, const std::vector<uint8_t> &m) {
  uint8_t full[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  HMAC(EVP_sha256(), key.data(), static_cast<int>(key.size()), m.data(), m.size(), full, &n);
  Mac out{};
  std::copy(full, full + kMacBytes, out.begin());
  return out;
}

std::string source_problem(const std::string &source) {
  if (source.empty()) return "empty source id";
  if (source.size() > kMaxSourceChars)
    return "source id longer than " + std::to_string(kMaxSourceChars) + " characters";
  for (char ch : source)
    if (ch < 0x21 || ch > 0x7e) return "source id has a character that is not printable ASCII";
  return "";
}

std::optional<Signer> load_machine_signer(const char *program, const std::string &vehicle,
                                          const std::string &key_file, const std::string &source) {
  try {
    return Signer(load_key(key_file.empty() ? default_key_path(vehicle) : key_file), vehicle,
                  source, kAuthorityMachine);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "%s: --key-file: %s\n", program, e.what());
    return std::nullopt;
  }
}

Signer::Signer(const Key &key, std::string vehicle, std::string source, int8_t authority)
    : key_(key), vehicle_(std::move(vehicle)), source_(std::move(source)), authority_(authority) {
  if (const std::string why = source_problem(source_); !why.empty())
    throw InputError("command signer: source '" + source_ + "': " + why);
  if (authority_ != autodrive::auth::kAuthorityMachine &&
      authority_ != autodrive::auth::kAuthorityPerson)
    throw InputError("command signer: authority " + std::to_string(authority_) +
                     " is neither AUTHORITY_MACHINE nor AUTHORITY_PERSON");
}

void Signer::sign(autodrive::vehicle_command_t &c) {
  c.source = source_;
  c.authority = authority_;
  last_counter_ = std::max(last_counter_ + 1, wall_us());
  c.counter = last_counter_;
  const Mac m = mac_of(key_, canonical_bytes(c, vehicle_));
  std::copy(m.begin(), m.end(), c.mac);
}

MacCheck check_mac(const Key &key, const std::string &vehicle,
                   const autodrive::vehicle_command_t &c) {
  const bool zero = std::all_of(c.mac, c.mac + kMacBytes, [](uint8_t b) { return b == 0; });
  if (c.source.empty() || c.authority == 0 || zero) return MacCheck::unsigned_cmd;
  const Mac want = mac_of(key, canonical_bytes(c, vehicle));
  return CRYPTO_memcmp(want.data(), c.mac, kMacBytes) == 0 ? MacCheck::ok : MacCheck::bad_mac;
}

}  // namespace autodrive::auth
