/* The message codec: a message's payload to its typed struct and back.
 * One table (sb_codec.c) gives each known type its payload size and its
 * fields' wire kinds and positions. */
#ifndef SB_CODEC_H
#define SB_CODEC_H

#include <stddef.h>
#include <stdint.h>

#include "sb_error.h"
#include "sb_msg.h"

#define SB_MAX_FIELDS 6

/* Whether the codec knows a type code. */
bool sb_type_known(uint8_t type);

/* The payload size of a known type; -1 for an unknown one. */
int sb_payload_size(uint8_t type);

/* The type's name as in records.py ("Move"); NULL for an unknown one. */
const char *sb_type_name(uint8_t type);

/* Whether a known type is one of the simulation's (StepTo, GetTruth, Truth, StepDone). */
bool sb_type_simulation(uint8_t type);

/* A message from its type and payload (n <= 8).  A type the codec does not
 * know is kept whole (out->known false, body.raw).  SB_ERR_PAYLOAD_SIZE for a
 * known type of another size, SB_ERR_PADDING for a reserved byte not zero,
 * SB_ERR_MSG_LENGTH for n above 8. */
sb_err sb_msg_decode(uint8_t type, const uint8_t *payload, size_t n, sb_msg *out);

/* The payload of a message into out (8 bytes); *n its length.  SB_ERR_RANGE
 * for a value its wire field cannot hold (a MotorTelemetry channel or mode
 * above 15, a raw payload above 8 bytes), SB_ERR_UNKNOWN_TYPE for a message
 * marked known whose type is not. */
sb_err sb_msg_encode(const sb_msg *msg, uint8_t out[SB_MAX_PAYLOAD], size_t *n);

/* Generic access to a known message's fields, in records.py's order (for
 * tools, logs and tests): how many, the i-th value, and setting it (a
 * message of that type is set up first with sb_msg_init).  sb_msg_set_field
 * returns SB_ERR_RANGE for a value outside the field's C type or wire range. */
int sb_msg_field_count(uint8_t type);
int64_t sb_msg_field(const sb_msg *msg, int i);
sb_err sb_msg_init(sb_msg *msg, uint8_t type);
sb_err sb_msg_set_field(sb_msg *msg, int i, int64_t value);

#endif
