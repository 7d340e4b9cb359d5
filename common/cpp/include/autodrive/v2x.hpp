// Signed V2X messages in C++: the generated LCM types that carry `auth` (V2V, V2I, light
// commands and states, Eye poses) signed and checked with <autodrive_v2x/v2x_auth.h>. Which
// roles may sign a channel: AUTODRIVE_CH_<ID>_SIGNED_BY of <autodrive_channels.h>
// (lcm_types/channels.yaml). Refusals are counted by reason and logged at a bounded rate,
// naming the channel, the sender and the reason.
#pragma once

#include <autodrive_v2x/v2x_auth.h>

#include <autodrive/log_limiter.hpp>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace autodrive::v2x {

// The LCM encoding of m with an empty auth: the bytes the signature covers.
template <class Msg>
std::vector<uint8_t> unsigned_payload(const Msg &m) {
  Msg copy = m;
  copy.auth_len = 0;
  copy.auth.clear();
  std::vector<uint8_t> buf(static_cast<size_t>(copy.getEncodedSize()));
  copy.encode(buf.data(), 0, static_cast<int>(buf.size()));
  return buf;
}

class Signer {
 public:
  // NAME.cert and NAME.sk from $AUTODRIVE_KEY_DIR (tools/keys issue); nullopt after printing
  // the reason, naming the file and the program.
  static std::optional<Signer> load(const std::string &program, const std::string &name) {
    char err[512] = "";
    v2x_signer_t *s = v2x_signer_load(nullptr, name.c_str(), err, sizeof err);
    if (!s) {
      std::fprintf(stderr, "%s: cannot sign as %s: %s\n", program.c_str(), name.c_str(), err);
      return std::nullopt;
    }
    return Signer(s);
  }

  // Signs m for channel, stamped with the sender's clock [us] (sim time in HIL).
  template <class Msg>
  void sign(const std::string &channel, Msg &m, int64_t sender_utime) {
    const auto payload = unsigned_payload(m);
    uint8_t out[V2X_MAX_ENVELOPE_BYTES];
    const size_t n = v2x_sign(signer_.get(), channel.c_str(), payload.data(), payload.size(),
                              sender_utime, out, sizeof out);
    m.auth.assign(out, out + n);
    m.auth_len = static_cast<int16_t>(n);
  }

  const v2x_cert_t &cert() const { return *v2x_signer_cert(signer_.get()); }

 private:
  struct Free {
    void operator()(v2x_signer_t *s) const { v2x_signer_destroy(s); }
  };
  explicit Signer(v2x_signer_t *s) : signer_(s) {}
  std::unique_ptr<v2x_signer_t, Free> signer_;
};

class Verifier {
 public:
  // The trust anchor and revocation list of $AUTODRIVE_KEY_DIR/ca; nullopt after printing the
  // reason.
  static std::optional<Verifier> load(const std::string &program) {
    char err[512] = "";
    v2x_verifier_t *v = v2x_verifier_create(nullptr, err, sizeof err);
    if (!v) {
      std::fprintf(stderr, "%s: cannot check signed messages: %s\n", program.c_str(), err);
      return std::nullopt;
    }
    return Verifier(v, program);
  }

  // True when m on channel is signed by a certificate of one of `roles` (a comma list,
  // AUTODRIVE_CH_<ID>_SIGNED_BY) named `name` (nullptr: any), and fresh on the receiver's
  // clock now_us [us]. Checks the revocation list (a stat) 4 times a second of now_us. sender
  // (may be nullptr) gets the certificate's name, serial and role as far as they were read.
  template <class Msg>
  bool accept(const std::string &channel, const Msg &m, const char *roles, const char *name,
              int64_t now_us, v2x_sender_t *sender_out = nullptr) {
    // (now_us < last: a clock that went back, such as a new simulator run)
    if (!last_reload_us_ || now_us < *last_reload_us_ || now_us - *last_reload_us_ >= 250000) {
      last_reload_us_ = now_us;
      char err[512] = "";
      if (v2x_verifier_reload(verifier_.get(), err, sizeof err) != 0)
        limiter_->event("revocation list", err);
    }
    const auto payload = unsigned_payload(m);
    v2x_sender_t sender;
    const v2x_reason_t r =
        v2x_verify(verifier_.get(), channel.c_str(), payload.data(), payload.size(), m.auth.data(),
                   m.auth.size(), v2x_role_mask(roles), name, now_us,
                   static_cast<int64_t>(std::time(nullptr)), &sender);
    if (sender_out) *sender_out = sender;
    if (r == V2X_OK) return true;
    const std::string who = sender.name[0] ? std::string("sender ") + sender.name + " (serial " +
                                                 std::to_string(sender.serial) + ")"
                                           : std::string("unknown sender");
    limiter_->event(channel, "dropped a message from " + who + ": " + v2x_reason_name(r));
    return false;
  }

  // Freshness window around the receiver's clock [us] (default V2X_DEFAULT_WINDOW_US).
  void set_window_us(int64_t window_us) { v2x_verifier_set_window_us(verifier_.get(), window_us); }

  uint64_t count(v2x_reason_t reason) const { return v2x_verifier_count(verifier_.get(), reason); }
  uint64_t refused() const {
    uint64_t n = 0;
    for (int r = 1; r < V2X_REASON_COUNT; ++r) n += count(static_cast<v2x_reason_t>(r));
    return n;
  }
  // {"forged signature": 3, "replayed": 1}: the refusals by reason as a JSON object (every
  // reason, 0s too, so that a reader tells "none refused" from "not counted").
  std::string counts_json() const {
    std::string out = "{";
    for (int r = 1; r < V2X_REASON_COUNT; ++r)
      out += (r > 1 ? ", \"" : "\"") + std::string(v2x_reason_name(static_cast<v2x_reason_t>(r))) +
             "\": " + std::to_string(count(static_cast<v2x_reason_t>(r)));
    return out + "}";
  }
  // "forged signature=3 replayed=1" (refusals only; "" when none).
  std::string summary() const {
    std::string out;
    for (int r = 1; r < V2X_REASON_COUNT; ++r) {
      const uint64_t n = count(static_cast<v2x_reason_t>(r));
      if (n)
        out += (out.empty() ? "" : ", ") +
               std::string(v2x_reason_name(static_cast<v2x_reason_t>(r))) + "=" + std::to_string(n);
    }
    return out;
  }

 private:
  struct Free {
    void operator()(v2x_verifier_t *v) const { v2x_verifier_destroy(v); }
  };
  Verifier(v2x_verifier_t *v, const std::string &program)
      : verifier_(v),
        limiter_(std::make_unique<autodrive::LogLimiter>(program + " refused messages")) {}
  std::unique_ptr<v2x_verifier_t, Free> verifier_;
  std::unique_ptr<autodrive::LogLimiter> limiter_;
  std::optional<int64_t> last_reload_us_;  // [us, the receiver's clock]
};

}  // namespace autodrive::v2x
