/* Signed V2X messages (see <autodrive_v2x/v2x_auth.h> and docs/design/threat-model.md). */
#define _POSIX_C_SOURCE 200809L
#include "autodrive_v2x/v2x_auth.h"

#include <sodium.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

static const uint8_t CERT_MAGIC[6] = {'A', 'D', 'C', 'R', 'T', '1'};
static const uint8_t CRL_MAGIC[6] = {'A', 'D', 'C', 'R', 'L', '1'};
static const uint8_t ENV_MAGIC[6] = {'A', 'D', 'S', 'I', 'G', '1'};
#define MAGIC_BYTES 6
#define CERT_HEAD_BYTES (MAGIC_BYTES + 8 + 1 + 1)
#define CERT_MAX_BYTES (CERT_HEAD_BYTES + V2X_MAX_NAME_CHARS + 16 + 32 + 64)
#define MAX_FILE_BYTES 65536
#define CERT_CACHE_SLOTS 64 /* certificates whose CA signature was checked */
#define SENDER_SLOTS 256    /* senders whose last counter is kept */
#define MAX_REVOKED 4096

static uint64_t get_u64(const uint8_t *p) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | p[i];
  return v;
}

static void put_u64(uint8_t *p, uint64_t v) {
  for (int i = 7; i >= 0; --i) {
    p[i] = (uint8_t)(v & 0xFF);
    v >>= 8;
  }
}

const char *v2x_reason_name(v2x_reason_t reason) {
  static const char *const names[V2X_REASON_COUNT] = {"accepted",
                                                      "unsigned",
                                                      "malformed envelope",
                                                      "malformed certificate",
                                                      "unknown authority",
                                                      "certificate not yet valid",
                                                      "certificate expired",
                                                      "certificate revoked",
                                                      "wrong role for this channel",
                                                      "wrong name for this message",
                                                      "forged signature",
                                                      "stale (outside the time window)",
                                                      "replayed (counter not newer)"};
  return (unsigned)reason < V2X_REASON_COUNT ? names[reason] : "unknown reason";
}

const char *v2x_role_name(int role) {
  switch (role) {
    case V2X_ROLE_CAR: return "car";
    case V2X_ROLE_SCM: return "scm";
    case V2X_ROLE_EYE: return "eye";
    case V2X_ROLE_LIGHT_CONTROLLER: return "light-controller";
    case V2X_ROLE_OPERATOR: return "operator";
    default: return "unknown";
  }
}

unsigned v2x_role_mask(const char *names) {
  unsigned mask = 0;
  const char *p = names;
  while (p && *p) {
    const char *end = strchr(p, ',');
    size_t n = end ? (size_t)(end - p) : strlen(p);
    int found = 0;
    for (int r = V2X_ROLE_CAR; r <= V2X_ROLE_OPERATOR; ++r) {
      const char *rn = v2x_role_name(r);
      if (strlen(rn) == n && strncmp(rn, p, n) == 0) {
        mask |= 1u << r;
        found = 1;
      }
    }
    if (!found) return 0;
    p = end ? end + 1 : NULL;
  }
  return mask;
}

v2x_reason_t v2x_cert_decode(const uint8_t *data, size_t len, v2x_cert_t *out) {
  memset(out, 0, sizeof *out);
  if (len < CERT_HEAD_BYTES || memcmp(data, CERT_MAGIC, MAGIC_BYTES) != 0)
    return V2X_MALFORMED_CERTIFICATE;
  size_t name_len = data[MAGIC_BYTES + 9];
  if (name_len < 1 || name_len > V2X_MAX_NAME_CHARS ||
      len != CERT_HEAD_BYTES + name_len + 16 + V2X_PUBLIC_KEY_BYTES + V2X_SIGNATURE_BYTES)
    return V2X_MALFORMED_CERTIFICATE;
  out->serial = get_u64(data + MAGIC_BYTES);
  out->role = data[MAGIC_BYTES + 8];
  if (out->role < V2X_ROLE_CAR || out->role > V2X_ROLE_OPERATOR) return V2X_MALFORMED_CERTIFICATE;
  for (size_t i = 0; i < name_len; ++i) {
    uint8_t c = data[CERT_HEAD_BYTES + i];
    if (c < 0x21 || c > 0x7E) return V2X_MALFORMED_CERTIFICATE;
    out->name[i] = (char)c;
  }
  const uint8_t *p = data + CERT_HEAD_BYTES + name_len;
  out->not_before_s = (int64_t)get_u64(p);
  out->not_after_s = (int64_t)get_u64(p + 8);
  memcpy(out->public_key, p + 16, V2X_PUBLIC_KEY_BYTES);
  out->body_len = len - V2X_SIGNATURE_BYTES;
  return V2X_OK;
}

/* --- files ------------------------------------------------------------------------------ */

static void key_dir_path(const char *key_dir, const char *file, char *out, size_t cap) {
  if (key_dir && *key_dir) {
    snprintf(out, cap, "%s/%s", key_dir, file);
    return;
  }
  const char *env = getenv("AUTODRIVE_KEY_DIR");
  if (env && *env) {
    snprintf(out, cap, "%s/%s", env, file);
    return;
  }
  const char *xdg = getenv("XDG_CONFIG_HOME");
  const char *home = getenv("HOME");
  if (xdg && *xdg)
    snprintf(out, cap, "%s/autodrive/keys/%s", xdg, file);
  else
    snprintf(out, cap, "%s/.config/autodrive/keys/%s", home ? home : ".", file);
}

/* Reads a one-line base64 file into out; returns its length, or -1 with err naming the file. */
static long read_b64_file(const char *path, const char *what, uint8_t *out, size_t cap, char *err,
                          size_t err_len) {
  FILE *f = fopen(path, "rb");
  if (!f) {
    snprintf(err, err_len, "%s: cannot read the %s (make it with tools/keys)", path, what);
    return -1;
  }
  char *text = malloc(MAX_FILE_BYTES + 1);
  size_t n = text ? fread(text, 1, MAX_FILE_BYTES, f) : 0;
  fclose(f);
  if (!text) {
    snprintf(err, err_len, "%s: out of memory", path);
    return -1;
  }
  while (n > 0 && (text[n - 1] == '\n' || text[n - 1] == '\r' || text[n - 1] == ' ')) --n;
  text[n] = '\0';
  size_t bin_len = 0;
  int bad =
      sodium_base642bin(out, cap, text, n, NULL, &bin_len, NULL, sodium_base64_VARIANT_ORIGINAL);
  free(text);
  if (bad) {
    snprintf(err, err_len, "%s: the %s is not one line of base64 (or too long)", path, what);
    return -1;
  }
  return (long)bin_len;
}

/* --- sender ----------------------------------------------------------------------------- */

struct v2x_signer {
  v2x_cert_t cert;
  uint8_t cert_bytes[CERT_MAX_BYTES];
  size_t cert_len;
  uint8_t secret_key[crypto_sign_SECRETKEYBYTES];
  uint64_t counter;
};

/* libsodium initialised and `size` zeroed bytes; NULL with the reason in err. */
static void *sodium_calloc_or_say(size_t size, char *err, size_t err_len) {
  if (sodium_init() < 0) {
    snprintf(err, err_len, "libsodium failed to initialise");
    return NULL;
  }
  void *p = calloc(1, size);
  if (!p) snprintf(err, err_len, "out of memory");
  return p;
}

v2x_signer_t *v2x_signer_load(const char *key_dir, const char *name, char *err, size_t err_len) {
  v2x_signer_t *s = sodium_calloc_or_say(sizeof *s, err, err_len);
  if (!s) return NULL;
  char path[1024], file[64];
  snprintf(file, sizeof file, "%s.cert", name);
  key_dir_path(key_dir, file, path, sizeof path);
  long n = read_b64_file(path, "certificate", s->cert_bytes, sizeof s->cert_bytes, err, err_len);
  if (n < 0) goto fail;
  s->cert_len = (size_t)n;
  if (v2x_cert_decode(s->cert_bytes, s->cert_len, &s->cert) != V2X_OK) {
    snprintf(err, err_len, "%s: malformed certificate", path);
    goto fail;
  }
  uint8_t seed[64];
  snprintf(file, sizeof file, "%s.sk", name);
  key_dir_path(key_dir, file, path, sizeof path);
  n = read_b64_file(path, "private key", seed, sizeof seed, err, err_len);
  if (n < 0) goto fail;
  if (n != crypto_sign_SEEDBYTES) {
    snprintf(err, err_len, "%s: a private key has %d bytes, this one %ld", path,
             crypto_sign_SEEDBYTES, n);
    goto fail;
  }
  uint8_t pk[crypto_sign_PUBLICKEYBYTES];
  crypto_sign_seed_keypair(pk, s->secret_key, seed);
  sodium_memzero(seed, sizeof seed);
  if (memcmp(pk, s->cert.public_key, sizeof pk) != 0) {
    snprintf(err, err_len, "%s: not the key of %s.cert", path, name);
    goto fail;
  }
  return s;
fail:
  v2x_signer_destroy(s);
  return NULL;
}

void v2x_signer_destroy(v2x_signer_t *signer) {
  if (!signer) return;
  sodium_memzero(signer, sizeof *signer);
  free(signer);
}

const v2x_cert_t *v2x_signer_cert(const v2x_signer_t *signer) {
  return &signer->cert;
}

/* The bytes an envelope's signature covers:
 * "ADSIG1" | channel_len u8 | channel | serial u64 | counter u64 | sender_utime i64 | payload. */
static uint8_t *signed_bytes(const char *channel, uint64_t serial, uint64_t counter,
                             int64_t sender_utime, const uint8_t *payload, size_t payload_len,
                             size_t *out_len) {
  size_t ch = strlen(channel);
  if (ch > 255) ch = 255;
  size_t len = MAGIC_BYTES + 1 + ch + 24 + payload_len;
  uint8_t *m = malloc(len);
  if (!m) return NULL;
  uint8_t *p = m;
  memcpy(p, ENV_MAGIC, MAGIC_BYTES);
  p += MAGIC_BYTES;
  *p++ = (uint8_t)ch;
  memcpy(p, channel, ch);
  p += ch;
  put_u64(p, serial);
  put_u64(p + 8, counter);
  put_u64(p + 16, (uint64_t)sender_utime);
  if (payload_len) memcpy(p + 24, payload, payload_len);
  *out_len = len;
  return m;
}

size_t v2x_sign(v2x_signer_t *signer, const char *channel, const uint8_t *payload,
                size_t payload_len, int64_t sender_utime, uint8_t *out, size_t out_cap) {
  size_t need = MAGIC_BYTES + 2 + signer->cert_len + 16 + V2X_SIGNATURE_BYTES;
  if (out_cap < need) return 0;
  /* Strictly increasing across restarts too: at least the wall clock [us]. */
  struct timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  uint64_t wall_us = (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
  signer->counter = signer->counter + 1 > wall_us ? signer->counter + 1 : wall_us;
  size_t m_len = 0;
  uint8_t *m = signed_bytes(channel, signer->cert.serial, signer->counter, sender_utime, payload,
                            payload_len, &m_len);
  if (!m) return 0;
  uint8_t *p = out;
  memcpy(p, ENV_MAGIC, MAGIC_BYTES);
  p += MAGIC_BYTES;
  p[0] = (uint8_t)(signer->cert_len >> 8);
  p[1] = (uint8_t)(signer->cert_len & 0xFF);
  p += 2;
  memcpy(p, signer->cert_bytes, signer->cert_len);
  p += signer->cert_len;
  put_u64(p, signer->counter);
  put_u64(p + 8, (uint64_t)sender_utime);
  p += 16;
  crypto_sign_detached(p, NULL, m, m_len, signer->secret_key);
  free(m);
  return need;
}

/* --- receiver --------------------------------------------------------------------------- */

typedef struct {
  uint8_t bytes[CERT_MAX_BYTES];
  size_t len; /* 0: empty slot */
} cert_slot_t;

typedef struct {
  uint64_t serial;
  uint64_t last_counter;
  int used;
} sender_slot_t;

struct v2x_verifier {
  char key_dir[1024];
  uint8_t ca_public_key[crypto_sign_PUBLICKEYBYTES];
  int64_t window_us;
  uint64_t revoked[MAX_REVOKED];
  size_t revoked_count;
  struct timespec crl_mtime;
  cert_slot_t certs[CERT_CACHE_SLOTS];
  size_t next_cert_slot;
  sender_slot_t senders[SENDER_SLOTS];
  size_t next_sender_slot;
  uint64_t counts[V2X_REASON_COUNT];
};

static int load_crl(v2x_verifier_t *v, char *err, size_t err_len) {
  char path[1100];
  key_dir_path(v->key_dir, "ca/ca.crl", path, sizeof path);
  struct stat st;
  if (stat(path, &st) != 0) {
    snprintf(err, err_len, "%s: no revocation list (tools/keys ca init makes one)", path);
    return -1;
  }
  if (st.st_mtim.tv_sec == v->crl_mtime.tv_sec && st.st_mtim.tv_nsec == v->crl_mtime.tv_nsec)
    return 0;
  size_t cap = MAGIC_BYTES + 12 + 8 * MAX_REVOKED + V2X_SIGNATURE_BYTES;
  uint8_t *data = malloc(cap);
  if (!data) {
    snprintf(err, err_len, "out of memory");
    return -1;
  }
  long n = read_b64_file(path, "revocation list", data, cap, err, err_len);
  int rc = -1;
  if (n < 0) goto done;
  size_t len = (size_t)n;
  size_t head = MAGIC_BYTES + 12;
  if (len < head + V2X_SIGNATURE_BYTES || memcmp(data, CRL_MAGIC, MAGIC_BYTES) != 0) {
    snprintf(err, err_len, "%s: malformed revocation list (no ADCRL1 header)", path);
    goto done;
  }
  const uint8_t *c = data + MAGIC_BYTES + 8; /* after the issue time */
  uint32_t count = ((uint32_t)c[0] << 24) | ((uint32_t)c[1] << 16) | ((uint32_t)c[2] << 8) | c[3];
  if (count > MAX_REVOKED || len != head + 8u * count + V2X_SIGNATURE_BYTES) {
    snprintf(err, err_len, "%s: malformed revocation list (length does not match count)", path);
    goto done;
  }
  if (crypto_sign_verify_detached(data + len - V2X_SIGNATURE_BYTES, data, len - V2X_SIGNATURE_BYTES,
                                  v->ca_public_key) != 0) {
    snprintf(err, err_len, "%s: revocation list not signed by this CA", path);
    goto done;
  }
  for (uint32_t i = 0; i < count; ++i) v->revoked[i] = get_u64(data + head + 8u * i);
  v->revoked_count = count;
  v->crl_mtime = st.st_mtim;
  rc = 0;
done:
  free(data);
  return rc;
}

v2x_verifier_t *v2x_verifier_create(const char *key_dir, char *err, size_t err_len) {
  v2x_verifier_t *v = sodium_calloc_or_say(sizeof *v, err, err_len);
  if (!v) return NULL;
  if (key_dir) snprintf(v->key_dir, sizeof v->key_dir, "%s", key_dir);
  v->window_us = V2X_DEFAULT_WINDOW_US;
  char path[1100];
  key_dir_path(v->key_dir, "ca/ca.pub", path, sizeof path);
  uint8_t key[64];
  long n = read_b64_file(path, "CA public key", key, sizeof key, err, err_len);
  if (n != crypto_sign_PUBLICKEYBYTES) {
    if (n >= 0) snprintf(err, err_len, "%s: a CA public key has 32 bytes, this one %ld", path, n);
    free(v);
    return NULL;
  }
  memcpy(v->ca_public_key, key, sizeof v->ca_public_key);
  if (load_crl(v, err, err_len) != 0) {
    free(v);
    return NULL;
  }
  return v;
}

void v2x_verifier_destroy(v2x_verifier_t *verifier) {
  free(verifier);
}

void v2x_verifier_set_window_us(v2x_verifier_t *verifier, int64_t window_us) {
  verifier->window_us = window_us;
}

int v2x_verifier_reload(v2x_verifier_t *verifier, char *err, size_t err_len) {
  return load_crl(verifier, err, err_len);
}

void v2x_verifier_revoke(v2x_verifier_t *verifier, uint64_t serial) {
  if (verifier->revoked_count < MAX_REVOKED) verifier->revoked[verifier->revoked_count++] = serial;
}

uint64_t v2x_verifier_count(const v2x_verifier_t *verifier, v2x_reason_t reason) {
  return (unsigned)reason < V2X_REASON_COUNT ? verifier->counts[reason] : 0;
}

static int is_revoked(const v2x_verifier_t *v, uint64_t serial) {
  for (size_t i = 0; i < v->revoked_count; ++i)
    if (v->revoked[i] == serial) return 1;
  return 0;
}

/* Checks the CA's signature on a certificate, once per distinct certificate. */
static int cert_signed_by_ca(v2x_verifier_t *v, const uint8_t *bytes, size_t len, size_t body_len) {
  for (size_t i = 0; i < CERT_CACHE_SLOTS; ++i)
    if (v->certs[i].len == len && memcmp(v->certs[i].bytes, bytes, len) == 0) return 1;
  if (crypto_sign_verify_detached(bytes + body_len, bytes, body_len, v->ca_public_key) != 0)
    return 0;
  cert_slot_t *slot = &v->certs[v->next_cert_slot];
  v->next_cert_slot = (v->next_cert_slot + 1) % CERT_CACHE_SLOTS;
  memcpy(slot->bytes, bytes, len);
  slot->len = len;
  return 1;
}

static sender_slot_t *sender_slot(v2x_verifier_t *v, uint64_t serial) {
  for (size_t i = 0; i < SENDER_SLOTS; ++i)
    if (v->senders[i].used && v->senders[i].serial == serial) return &v->senders[i];
  /* A new sender takes the next slot in turn; an evicted sender's old messages are still
   * refused by the time window. */
  sender_slot_t *slot = &v->senders[v->next_sender_slot];
  v->next_sender_slot = (v->next_sender_slot + 1) % SENDER_SLOTS;
  slot->used = 1;
  slot->serial = serial;
  slot->last_counter = 0;
  return slot;
}

static v2x_reason_t check(v2x_verifier_t *v, const char *channel, const uint8_t *payload,
                          size_t payload_len, const uint8_t *auth, size_t auth_len,
                          unsigned allowed_roles, const char *required_name, int64_t now_us,
                          int64_t wall_s, v2x_sender_t *sender) {
  if (auth_len == 0) return V2X_UNSIGNED;
  if (auth_len < MAGIC_BYTES + 2 || memcmp(auth, ENV_MAGIC, MAGIC_BYTES) != 0)
    return V2X_MALFORMED_ENVELOPE;
  size_t cert_len = ((size_t)auth[MAGIC_BYTES] << 8) | auth[MAGIC_BYTES + 1];
  if (auth_len != MAGIC_BYTES + 2 + cert_len + 16 + V2X_SIGNATURE_BYTES)
    return V2X_MALFORMED_ENVELOPE;
  const uint8_t *cert_bytes = auth + MAGIC_BYTES + 2;
  v2x_cert_t cert;
  if (v2x_cert_decode(cert_bytes, cert_len, &cert) != V2X_OK) return V2X_MALFORMED_CERTIFICATE;
  memcpy(sender->name, cert.name, sizeof sender->name);
  sender->serial = cert.serial;
  sender->role = cert.role;
  if (!cert_signed_by_ca(v, cert_bytes, cert_len, cert.body_len)) return V2X_UNKNOWN_AUTHORITY;
  if (wall_s < cert.not_before_s) return V2X_NOT_YET_VALID;
  if (wall_s > cert.not_after_s) return V2X_EXPIRED;
  if (is_revoked(v, cert.serial)) return V2X_REVOKED;
  if (!(allowed_roles & (1u << cert.role))) return V2X_WRONG_ROLE;
  if (required_name && strcmp(required_name, cert.name) != 0) return V2X_WRONG_NAME;
  const uint8_t *tail = cert_bytes + cert_len;
  uint64_t counter = get_u64(tail);
  int64_t sender_utime = (int64_t)get_u64(tail + 8);
  size_t m_len = 0;
  uint8_t *m =
      signed_bytes(channel, cert.serial, counter, sender_utime, payload, payload_len, &m_len);
  if (!m) return V2X_MALFORMED_ENVELOPE;
  int bad = crypto_sign_verify_detached(tail + 16, m, m_len, cert.public_key);
  free(m);
  if (bad) return V2X_BAD_SIGNATURE;
  int64_t age_us = now_us - sender_utime;
  if (age_us > v->window_us || age_us < -v->window_us) return V2X_STALE;
  sender_slot_t *slot = sender_slot(v, cert.serial);
  if (counter <= slot->last_counter) return V2X_REPLAYED;
  slot->last_counter = counter;
  return V2X_OK;
}

v2x_reason_t v2x_verify(v2x_verifier_t *verifier, const char *channel, const uint8_t *payload,
                        size_t payload_len, const uint8_t *auth, size_t auth_len,
                        unsigned allowed_roles, const char *required_name, int64_t now_us,
                        int64_t wall_s, v2x_sender_t *sender) {
  v2x_sender_t local;
  v2x_sender_t *out = sender ? sender : &local;
  memset(out, 0, sizeof *out);
  v2x_reason_t r = check(verifier, channel, payload, payload_len, auth, auth_len, allowed_roles,
                         required_name, now_us, wall_s, out);
  verifier->counts[r]++;
  return r;
}
