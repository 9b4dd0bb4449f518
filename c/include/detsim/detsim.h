/* detsim's C API: worlds, bodies and shapes, stepping, save and restore, state hashes, queries
 * and rollback or lockstep sessions driving a game through callbacks, for engines and languages
 * that bind to C (C#, Rust, Godot, Unity, Python's ctypes). docs/C_API.md has the rules and an
 * example.
 *
 * - Numbers are Q32.32 fixed point, passed as their raw 64-bit value (detsim_fixed: 1.0 is
 *   DETSIM_FIXED_ONE). Make them exactly with detsim_fixed_from_int or detsim_fixed_parse (decimal
 *   text, correctly rounded); detsim_fixed_to_double is for display only: a simulation fed from
 *   doubles is deterministic only if the doubles are.
 * - Every call that can fail returns a detsim_result; DETSIM_OK is 0. On failure it changes
 *   nothing, and detsim_last_error() says why ("body definition: radius must be > 0 ...").
 * - No C++ exception crosses this boundary, and no C++ type appears here.
 * - A world is used by one thread at a time; distinct worlds are independent.
 */
#ifndef DETSIM_DETSIM_H
#define DETSIM_DETSIM_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- Numbers ---- */

typedef int64_t detsim_fixed; /* Q32.32: the value times 2^32 */
#define DETSIM_FIXED_ONE ((detsim_fixed)1 << 32)

typedef struct detsim_vec3 {
  detsim_fixed x, y, z;
} detsim_vec3;

typedef struct detsim_quat { /* a unit quaternion; the identity is {DETSIM_FIXED_ONE, 0, 0, 0} */
  detsim_fixed w, x, y, z;
} detsim_quat;

typedef enum detsim_result {
  DETSIM_OK = 0,
  DETSIM_INVALID_ARGUMENT = 1, /* a null pointer, an unknown ID, a value the world refuses */
  DETSIM_BUFFER_TOO_SMALL = 2, /* the size needed was written; call again with a larger buffer */
  DETSIM_OUT_OF_MEMORY = 3,
  DETSIM_INTERNAL_ERROR = 4 /* a bug: please report it with detsim_last_error() */
} detsim_result;

/* The message of this thread's last failed call, "" when the last call succeeded. Valid until the
 * thread's next call into detsim. */
const char* detsim_last_error(void);
/* The library's version, "MAJOR.MINOR.PATCH". */
const char* detsim_version(void);

detsim_fixed detsim_fixed_from_int(int32_t value);
/* Decimal text ("0.25", "-9.81", "1e-3") to the nearest Q32.32 value (ties to even). */
detsim_result detsim_fixed_parse(const char* text, detsim_fixed* out);
double detsim_fixed_to_double(detsim_fixed value);

/* ---- Worlds ---- */

typedef struct detsim_world detsim_world;

/* The most used settings of a world; detsim_world_def_init fills every field with the defaults
 * (60 Hz, 4 sub-steps, gravity -9.81 m/s^2 along y, seed 0). */
typedef struct detsim_world_def {
  detsim_vec3 gravity; /* m/s^2 */
  detsim_fixed dt;     /* s per step */
  uint32_t substeps;
  uint32_t iterations;
  uint64_t seed; /* the world's random number generator */
} detsim_world_def;

void detsim_world_def_init(detsim_world_def* def);
/* def may be NULL (the defaults). The world is written to *out; destroy it with
 * detsim_world_destroy. */
detsim_result detsim_world_create(const detsim_world_def* def, detsim_world** out);
void detsim_world_destroy(detsim_world* world); /* NULL is fine */
detsim_result detsim_world_step(detsim_world* world);
uint64_t detsim_world_frame(const detsim_world* world); /* 0 for NULL */
/* The state in the canonical encoding (docs/STATE.md), identical on every machine. With
 * capacity too small (or buffer NULL) nothing is written but *size, and the result is
 * DETSIM_BUFFER_TOO_SMALL (DETSIM_OK when buffer is NULL and capacity 0: a size query). */
detsim_result detsim_world_save(const detsim_world* world, uint8_t* buffer, size_t capacity,
                                size_t* size);
/* Replaces the whole state; bytes that do not restore change nothing (the reason is in
 * detsim_last_error, naming the byte and the field). */
detsim_result detsim_world_restore(detsim_world* world, const uint8_t* bytes, size_t size);
/* The per-frame state hash (XXH3-64 of the canonical state): what peers compare. */
detsim_result detsim_world_hash(const detsim_world* world, uint64_t* out);

/* ---- Bodies and shapes ---- */

typedef enum detsim_shape_type {
  DETSIM_SHAPE_SPHERE = 1,  /* radius */
  DETSIM_SHAPE_BOX = 2,     /* half_extents */
  DETSIM_SHAPE_CAPSULE = 3, /* radius, half_height: along the local y axis */
  DETSIM_SHAPE_PLANE = 4,   /* the half-space below local y = 0; static bodies only */
  DETSIM_SHAPE_CYLINDER = 5 /* radius, half_height: along the local y axis */
} detsim_shape_type;

typedef struct detsim_shape {
  uint32_t type; /* a detsim_shape_type */
  detsim_fixed radius;
  detsim_fixed half_height;
  detsim_vec3 half_extents;
} detsim_shape;

typedef enum detsim_body_type {
  DETSIM_BODY_STATIC = 0,
  DETSIM_BODY_KINEMATIC = 1,
  DETSIM_BODY_DYNAMIC = 2
} detsim_body_type;

/* detsim_body_def_init fills the defaults: dynamic, a 0.5 m sphere at the origin, density 1000,
 * friction 0.6, collides with everything. */
typedef struct detsim_body_def {
  uint32_t type; /* a detsim_body_type */
  detsim_shape shape;
  detsim_vec3 position;
  detsim_quat orientation;
  detsim_vec3 linear_velocity;
  detsim_vec3 angular_velocity;
  detsim_fixed mass; /* kg; 0: density times volume */
  detsim_fixed density;
  detsim_fixed friction;
  detsim_fixed restitution;
  uint32_t layer;
  uint32_t mask;
  uint64_t user_data;
} detsim_body_def;

typedef struct detsim_body_state {
  uint32_t id;
  uint32_t type;
  detsim_vec3 position;
  detsim_quat orientation;
  detsim_vec3 linear_velocity;
  detsim_vec3 angular_velocity;
  detsim_fixed mass;
  int awake;
  uint64_t user_data;
} detsim_body_state;

void detsim_body_def_init(detsim_body_def* def);
/* A refused definition creates nothing and consumes no ID. */
detsim_result detsim_body_create(detsim_world* world, const detsim_body_def* def, uint32_t* id);
detsim_result detsim_body_destroy(detsim_world* world, uint32_t id);
detsim_result detsim_body_get(const detsim_world* world, uint32_t id, detsim_body_state* out);
detsim_result detsim_body_apply_force(detsim_world* world, uint32_t id, detsim_vec3 force);
detsim_result detsim_body_apply_impulse(detsim_world* world, uint32_t id, detsim_vec3 impulse);
detsim_result detsim_body_set_linear_velocity(detsim_world* world, uint32_t id,
                                              detsim_vec3 velocity);

/* ---- Queries ---- */

typedef struct detsim_hit {
  uint32_t body;
  detsim_vec3 point;
  detsim_vec3 normal;
  detsim_fixed fraction;
} detsim_hit;

/* The first body a ray meets: *found is 1 and *hit filled, or *found is 0. */
detsim_result detsim_world_raycast(const detsim_world* world, detsim_vec3 origin,
                                   detsim_vec3 translation, detsim_hit* hit, int* found);
/* The first body a shape meets moving along translation without turning (World::shape_cast). */
detsim_result detsim_world_shape_cast(const detsim_world* world, const detsim_shape* shape,
                                      detsim_vec3 position, detsim_quat orientation,
                                      detsim_vec3 translation, detsim_hit* hit, int* found);

/* ---- Sessions: rollback and lockstep (docs/NET.md), over a seeded simulated network here and
 * over UDP or the game's own transport below ---- */

/* The game a session drives, GGPO's shape: the session decides when the game saves, loads and
 * advances. Every callback is called from inside detsim_session_poll or
 * detsim_session_advance_frame, on the calling thread, with `context`. */
typedef struct detsim_game {
  void* context;
  /* Writes the current state to a buffer the game allocates (*buffer, *size) and returns the
   * state's hash: two machines in the same state must return the same hash. */
  uint64_t (*save)(void* context, uint8_t** buffer, size_t* size);
  /* Frees a buffer save returned, once the session no longer needs it. */
  void (*free_buffer)(void* context, uint8_t* buffer);
  /* Returns the game to a state save wrote. */
  void (*load)(void* context, const uint8_t* buffer, size_t size);
  /* Simulates frame `frame` with players * input_size bytes of inputs (player order) and one
   * detsim_input_status per player; resimulating is 1 after a rollback (skip sounds and effects
   * already played). */
  void (*advance)(void* context, uint64_t frame, const uint8_t* inputs, uint32_t players,
                  uint32_t input_size, const uint8_t* status, int resimulating);
} detsim_game;

typedef enum detsim_input_status {
  DETSIM_INPUT_CONFIRMED = 0,
  DETSIM_INPUT_PREDICTED = 1,
  DETSIM_INPUT_DISCONNECTED = 2
} detsim_input_status;

/* One direction of a simulated link: integers only (a perfect link is all zero). */
typedef struct detsim_link {
  uint32_t latency_us;
  uint32_t jitter_us;
  uint32_t loss_ppm;
  uint32_t duplicate_ppm;
  uint32_t reorder_ppm;
} detsim_link;

typedef struct detsim_network detsim_network;
/* A network of `nodes` nodes, every link with *links (NULL: perfect), the clock at 0. The same
 * seed and calls give the same deliveries on every machine. */
detsim_result detsim_network_create(uint32_t nodes, uint64_t seed, const detsim_link* links,
                                    detsim_network** out);
/* Destroy a network after the sessions that use it. NULL is fine. */
void detsim_network_destroy(detsim_network* network);
/* Moves the virtual clock to now_us (never backwards): delivers what is due. */
detsim_result detsim_network_advance_to(detsim_network* network, uint64_t now_us);

typedef enum detsim_session_mode {
  DETSIM_MODE_ROLLBACK = 0,
  DETSIM_MODE_LOCKSTEP = 1
} detsim_session_mode;

/* detsim_session_config_init fills the defaults: rollback, 2 players, local player 0, 4-byte
 * inputs, input delay 2, prediction up to 8 frames. */
typedef struct detsim_session_config {
  uint32_t mode; /* a detsim_session_mode */
  uint32_t players;
  uint32_t local_player;
  uint32_t input_size;
  uint32_t input_delay;
  uint32_t max_prediction;
  uint64_t fingerprint; /* what peers must agree on (game, version, settings) */
} detsim_session_config;

typedef enum detsim_advance {
  DETSIM_ADVANCED = 0,          /* simulated one new frame (after any rollback) */
  DETSIM_SYNCHRONIZING = 1,     /* a peer's handshake is not done: nothing simulated */
  DETSIM_PREDICTION_LIMIT = 2,  /* rollback: too far ahead of the confirmed inputs */
  DETSIM_WAITING_FOR_INPUTS = 3 /* lockstep: an input of the next frame has not arrived */
} detsim_advance;

typedef struct detsim_session detsim_session;
void detsim_session_config_init(detsim_session_config* config);
/* A session for config->local_player at node local_player of `network`; player p is at node p.
 * The game's state is saved as frame 0. The network must outlive the session. */
detsim_result detsim_session_create(const detsim_session_config* config, const detsim_game* game,
                                    detsim_network* network, detsim_session** out);
void detsim_session_destroy(detsim_session* session); /* NULL is fine */
/* Receives, sends what is due, applies corrections (the game loads and re-simulates). */
detsim_result detsim_session_poll(detsim_session* session, uint64_t now_us);
/* Queues input_size bytes of local input and simulates the next frame if it may; *what says
 * what happened (a detsim_advance). */
detsim_result detsim_session_advance_frame(detsim_session* session, const uint8_t* input,
                                           size_t size, uint32_t* what);
uint64_t detsim_session_current_frame(const detsim_session* session);
/* The newest frame whose inputs every player confirmed; its states will not change. */
uint64_t detsim_session_confirmed_frame(const detsim_session* session);
/* The hash of the state after confirmed frame `frame`, once the session has simulated past it and
 * handed it on (the last 1024 such frames are kept). */
detsim_result detsim_session_confirmed_hash(const detsim_session* session, uint64_t frame,
                                            uint64_t* hash);

/* ---- Sessions over a real network: UDP, or the game's own transport ---- */

/* Where a session's datagrams go. Player p's datagrams are sent to, and received from, peer p.
 * Datagrams are at most DETSIM_MAX_DATAGRAM bytes; a transport is unreliable by contract (the
 * session's protocol checks every byte and resends what matters). */
#define DETSIM_MAX_DATAGRAM 1200
typedef struct detsim_transport detsim_transport;

/* A UDP socket bound to `bind` ("0.0.0.0:7000", "[::1]:0"; numeric addresses only, port 0: the
 * system picks one, see detsim_udp_local_port), non-blocking. Errors name the address and the
 * system's reason. In a build without sockets (DETSIM_WITH_UDP off, e.g. WebAssembly) this fails
 * with DETSIM_INVALID_ARGUMENT and says so: bring the network with detsim_transport_create. */
detsim_result detsim_udp_open(const char* bind, detsim_transport** out);
/* Tells a UDP transport where player `player` is ("192.0.2.10:7000"): its datagrams go there, and
 * only datagrams from exactly that address and port are taken as that player's. */
detsim_result detsim_udp_add_peer(detsim_transport* transport, uint32_t player,
                                  const char* address);
/* The port a UDP transport is bound to (the system's choice when bound to port 0). */
detsim_result detsim_udp_local_port(const detsim_transport* transport, uint16_t* port);

/* The game's own network (Steam, WebRTC, WebSocket, a relay): detsim calls `send` with each
 * datagram for player `player`, from inside detsim_session_poll or detsim_session_advance_frame;
 * the game passes every datagram it receives to detsim_transport_deliver. */
typedef void (*detsim_send_fn)(void* context, uint32_t player, const uint8_t* bytes, size_t size);
detsim_result detsim_transport_create(detsim_send_fn send, void* context, detsim_transport** out);
/* Queues a datagram received from player `from` for the session's next poll. More than
 * DETSIM_MAX_DATAGRAM bytes is refused (DETSIM_INVALID_ARGUMENT); at most 4096 datagrams wait
 * (more are dropped, as a network would). Only for transports made by detsim_transport_create. */
detsim_result detsim_transport_deliver(detsim_transport* transport, uint32_t from,
                                       const uint8_t* bytes, size_t size);
/* Destroy a transport after the session that uses it. NULL is fine. */
void detsim_transport_destroy(detsim_transport* transport);

/* A session for config->local_player whose peers are reached through `transport` (player p is
 * peer p). The game's state is saved as frame 0. The transport must outlive the session. */
detsim_result detsim_session_create_on(const detsim_session_config* config, const detsim_game* game,
                                       detsim_transport* transport, detsim_session** out);

#ifdef __cplusplus
}
#endif

#endif /* DETSIM_DETSIM_H */
