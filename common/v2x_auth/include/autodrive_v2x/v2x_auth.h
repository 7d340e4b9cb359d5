/* Signed V2X messages: the testbed's certificates and the envelope that V2V, <VEH>_V2I,
 * TRAFFIC_LIGHT_COMMAND, TRAFFIC_LIGHT_STATE and <VEH>_POSE_EYE carry in their `auth` field.
 * Ed25519 from libsodium; no crypto here. The byte layouts are documented once, in
 * docs/design/threat-model.md (certificates, revocation list, envelope); the Python side is
 * autodrive.core.v2x_cert / v2x_auth, and tests/foundation/v2x_vectors.json holds the vectors
 * both must match.
 *
 * The signed payload is the LCM encoding of the message with an empty auth field, so the
 * envelope does not depend on the message type. Time is passed in: the receiver's clock
 * (sim time in HIL) for freshness, wall time for a certificate's validity. */
#ifndef AUTODRIVE_V2X_AUTH_H
#define AUTODRIVE_V2X_AUTH_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define V2X_PUBLIC_KEY_BYTES 32
#define V2X_SIGNATURE_BYTES 64
#define V2X_MAX_NAME_CHARS 32
/* The largest envelope: header, the largest certificate, counter, time, signature [bytes]. */
#define V2X_MAX_ENVELOPE_BYTES 256
/* Default freshness window: a message's sender time must be within this of the receiver's
 * clock [us]; a replay 1 s late is stale whatever its counter. */
#define V2X_DEFAULT_WINDOW_US 500000

/* Roles as on the wire; masks are (1u << role). */
typedef enum {
  V2X_ROLE_CAR = 1,
  V2X_ROLE_SCM = 2,
  V2X_ROLE_EYE = 3,
  V2X_ROLE_LIGHT_CONTROLLER = 4,
  V2X_ROLE_OPERATOR = 5,
} v2x_role_t;

/* Why a message was refused; V2X_OK when accepted. */
typedef enum {
  V2X_OK = 0,
  V2X_UNSIGNED,           /* empty auth field */
  V2X_MALFORMED_ENVELOPE, /* wrong length or header */
  V2X_MALFORMED_CERTIFICATE,
  V2X_UNKNOWN_AUTHORITY, /* certificate not signed by this CA */
  V2X_NOT_YET_VALID,
  V2X_EXPIRED,
  V2X_REVOKED,
  V2X_WRONG_ROLE,    /* role not permitted on this channel */
  V2X_WRONG_NAME,    /* e.g. NIGEL2's certificate sending V2V as NIGEL1 */
  V2X_BAD_SIGNATURE, /* forged or altered */
  V2X_STALE,         /* sender time outside the window of the receiver's clock */
  V2X_REPLAYED,      /* counter not above the sender's last */
  V2X_REASON_COUNT
} v2x_reason_t;

/* A short name for the reason ("forged signature", "replayed", ...). */
const char *v2x_reason_name(v2x_reason_t reason);
/* The role's name as tools/keys takes it ("car", "scm", ...), "unknown" otherwise. */
const char *v2x_role_name(int role);
/* The mask of a comma-separated list of role names ("sim,light-controller" is not a role:
 * only the names of v2x_role_name); 0 on an unknown name. */
unsigned v2x_role_mask(const char *names);

typedef struct {
  uint64_t serial;
  int role;
  char name[V2X_MAX_NAME_CHARS + 1];
  int64_t not_before_s; /* unix time [s] */
  int64_t not_after_s;  /* unix time [s] */
  uint8_t public_key[V2X_PUBLIC_KEY_BYTES];
  size_t body_len; /* bytes the CA signed (the certificate less its signature) */
} v2x_cert_t;

/* Decodes a certificate (raw bytes); V2X_OK or V2X_MALFORMED_CERTIFICATE. No signature check. */
v2x_reason_t v2x_cert_decode(const uint8_t *data, size_t len, v2x_cert_t *out);

/* --- sender ---------------------------------------------------------------------------- */
typedef struct v2x_signer v2x_signer_t;

/* Loads NAME.cert and NAME.sk from key_dir (NULL: $AUTODRIVE_KEY_DIR, else
 * ~/.config/autodrive/keys). NULL on failure with the reason, naming the file, in err. */
v2x_signer_t *v2x_signer_load(const char *key_dir, const char *name, char *err, size_t err_len);
void v2x_signer_destroy(v2x_signer_t *signer);
const v2x_cert_t *v2x_signer_cert(const v2x_signer_t *signer);
/* Writes the envelope for payload on channel, stamped with sender_utime (the sender's clock
 * [us]) and the next counter, to out (at least V2X_MAX_ENVELOPE_BYTES); returns its length,
 * or 0 when payload cannot be signed (out of memory). */
size_t v2x_sign(v2x_signer_t *signer, const char *channel, const uint8_t *payload,
                size_t payload_len, int64_t sender_utime, uint8_t *out, size_t out_cap);

/* --- receiver -------------------------------------------------------------------------- */
typedef struct v2x_verifier v2x_verifier_t;

/* Loads the trust anchor (ca/ca.pub) and revocation list (ca/ca.crl) from key_dir (NULL: as
 * above). NULL on failure with the reason in err. */
v2x_verifier_t *v2x_verifier_create(const char *key_dir, char *err, size_t err_len);
void v2x_verifier_destroy(v2x_verifier_t *verifier);
void v2x_verifier_set_window_us(v2x_verifier_t *verifier, int64_t window_us);
/* Re-reads ca/ca.crl when its modification time changed; call it about once a second.
 * Returns 0, or -1 with the reason in err (the list held so far stays in force). */
int v2x_verifier_reload(v2x_verifier_t *verifier, char *err, size_t err_len);
/* Revokes a serial in memory (the SCM's list over the bus, and tests). */
void v2x_verifier_revoke(v2x_verifier_t *verifier, uint64_t serial);

typedef struct {
  char name[V2X_MAX_NAME_CHARS + 1]; /* the certificate's name, "" when none could be read */
  uint64_t serial;
  int role;
} v2x_sender_t;

/* Checks auth for payload on channel: the certificate against the CA, its validity at wall_s
 * (unix [s]), the revocation list, its role against allowed_roles (a v2x_role_mask), its name
 * against required_name (NULL: any), the signature, and freshness on the receiver's clock
 * now_us [us]. Counts the outcome; fills sender (may be NULL) as far as it could be read. */
v2x_reason_t v2x_verify(v2x_verifier_t *verifier, const char *channel, const uint8_t *payload,
                        size_t payload_len, const uint8_t *auth, size_t auth_len,
                        unsigned allowed_roles, const char *required_name, int64_t now_us,
                        int64_t wall_s, v2x_sender_t *sender);
/* Messages refused for a reason (V2X_OK: accepted) since the verifier was made [count]. */
uint64_t v2x_verifier_count(const v2x_verifier_t *verifier, v2x_reason_t reason);

#ifdef __cplusplus
}
#endif
#endif
