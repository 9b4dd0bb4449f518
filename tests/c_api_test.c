/* The C API from C11 (<detsim/detsim.h>): a ball dropped on a plane comes to rest on it, a saved
 * world restores into a second one that then steps to the same hashes, refusals name the field
 * and change nothing, NULL pointers are refused, queries hit where the geometry says, and two
 * rollback sessions driving the game through C callbacks agree on every confirmed frame's hash
 * over a lossy, jittery simulated network, over UDP on 127.0.0.1, and over the game's own
 * transport (callbacks) that drops one datagram in ten; bad transports are refused. Exit
 * status 0 when every check holds; each failure is printed with its line. */
#include <detsim/detsim.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failures = 0;

#define CHECK(condition)                                                      \
  do {                                                                        \
    if (!(condition)) {                                                       \
      fprintf(stderr, "%s:%d: failed: %s\n", __FILE__, __LINE__, #condition); \
      ++failures;                                                             \
    }                                                                         \
  } while (0)

static detsim_fixed fx(const char* text) {
  detsim_fixed value = 0;
  if (detsim_fixed_parse(text, &value) != DETSIM_OK) {
    fprintf(stderr, "cannot parse %s: %s\n", text, detsim_last_error());
    exit(2);
  }
  return value;
}

static detsim_fixed absolute(detsim_fixed x) {
  return x < 0 ? -x : x;
}

/* A world with a static ground plane and a 0.5 m ball (ID 2) 3 m up at x = 0. */
static detsim_world* ball_world(void) {
  detsim_world* world = NULL;
  CHECK(detsim_world_create(NULL, &world) == DETSIM_OK);
  detsim_body_def ground;
  detsim_body_def_init(&ground);
  ground.type = DETSIM_BODY_STATIC;
  ground.shape.type = DETSIM_SHAPE_PLANE;
  uint32_t id = 0;
  CHECK(detsim_body_create(world, &ground, &id) == DETSIM_OK && id == 1);
  detsim_body_def ball;
  detsim_body_def_init(&ball);
  ball.position.y = fx("3");
  CHECK(detsim_body_create(world, &ball, &id) == DETSIM_OK && id == 2);
  return world;
}

static void numbers(void) {
  CHECK(fx("0.5") == DETSIM_FIXED_ONE / 2);
  CHECK(fx("-9.81") == -(detsim_fixed)(9.81 * 4294967296.0 + 0.5));
  CHECK(detsim_fixed_from_int(-3) == -3 * DETSIM_FIXED_ONE);
  CHECK(detsim_fixed_to_double(DETSIM_FIXED_ONE / 4) == 0.25);
  detsim_fixed out = 7;
  CHECK(detsim_fixed_parse("1.2.3", &out) == DETSIM_INVALID_ARGUMENT);
  CHECK(out == 7);
  CHECK(strstr(detsim_last_error(), "1.2.3") != NULL);
  CHECK(strlen(detsim_version()) >= 5);
}

static void a_ball_comes_to_rest_on_the_plane(void) {
  detsim_world* world = ball_world();
  for (int i = 0; i < 180; ++i)
    CHECK(detsim_world_step(world) == DETSIM_OK);
  CHECK(detsim_world_frame(world) == 180);
  detsim_body_state ball;
  CHECK(detsim_body_get(world, 2, &ball) == DETSIM_OK);
  /* Resting: its centre a radius above the plane, within the contacts' 2 cm soft range. */
  CHECK(absolute(ball.position.y - DETSIM_FIXED_ONE / 2) < fx("0.02"));
  CHECK(absolute(ball.linear_velocity.y) < fx("0.01"));
  CHECK(ball.id == 2 && ball.type == DETSIM_BODY_DYNAMIC);
  detsim_world_destroy(world);
}

static void a_saved_world_restores_and_steps_alike(void) {
  detsim_world* a = ball_world();
  for (int i = 0; i < 20; ++i)
    detsim_world_step(a);
  size_t size = 0;
  CHECK(detsim_world_save(a, NULL, 0, &size) == DETSIM_OK && size > 0);
  uint8_t small[8];
  size_t needed = 0;
  CHECK(detsim_world_save(a, small, sizeof small, &needed) == DETSIM_BUFFER_TOO_SMALL);
  CHECK(needed == size);
  uint8_t* bytes = malloc(size);
  CHECK(bytes != NULL);
  CHECK(detsim_world_save(a, bytes, size, &needed) == DETSIM_OK && needed == size);

  detsim_world* b = NULL;
  CHECK(detsim_world_create(NULL, &b) == DETSIM_OK);
  CHECK(detsim_world_restore(b, bytes, size) == DETSIM_OK);
  for (int i = 0; i < 60; ++i) {
    uint64_t ha = 0;
    uint64_t hb = 0;
    CHECK(detsim_world_hash(a, &ha) == DETSIM_OK && detsim_world_hash(b, &hb) == DETSIM_OK);
    CHECK(ha == hb);
    detsim_world_step(a);
    detsim_world_step(b);
  }
  /* Corrupt bytes are refused, naming where, and change nothing. */
  uint64_t before = 0;
  detsim_world_hash(b, &before);
  bytes[size / 2] ^= 0xFF;
  bytes[0] ^= 0xFF;
  CHECK(detsim_world_restore(b, bytes, size) == DETSIM_INVALID_ARGUMENT);
  CHECK(strlen(detsim_last_error()) > 0);
  uint64_t after = 1;
  detsim_world_hash(b, &after);
  CHECK(before == after);
  free(bytes);
  detsim_world_destroy(a);
  detsim_world_destroy(b);
}

static void refusals_name_the_field_and_change_nothing(void) {
  detsim_world* world = ball_world();
  detsim_body_def bad;
  detsim_body_def_init(&bad);
  bad.shape.radius = 0;
  uint32_t id = 99;
  CHECK(detsim_body_create(world, &bad, &id) == DETSIM_INVALID_ARGUMENT);
  CHECK(strstr(detsim_last_error(), "radius") != NULL);
  CHECK(id == 99);
  bad.shape.type = 9;
  CHECK(detsim_body_create(world, &bad, &id) == DETSIM_INVALID_ARGUMENT);
  CHECK(strstr(detsim_last_error(), "shape type 9") != NULL);
  /* No ID was consumed: the next body is 3. */
  detsim_body_def good;
  detsim_body_def_init(&good);
  good.position.x = fx("4");
  CHECK(detsim_body_create(world, &good, &id) == DETSIM_OK && id == 3);
  CHECK(strcmp(detsim_last_error(), "") == 0);
  detsim_body_state state;
  CHECK(detsim_body_get(world, 42, &state) == DETSIM_INVALID_ARGUMENT);
  CHECK(strstr(detsim_last_error(), "42") != NULL);
  CHECK(detsim_body_get(NULL, 2, &state) == DETSIM_INVALID_ARGUMENT);
  CHECK(strstr(detsim_last_error(), "NULL") != NULL);
  CHECK(detsim_body_get(world, 2, NULL) == DETSIM_INVALID_ARGUMENT);
  CHECK(detsim_world_step(NULL) == DETSIM_INVALID_ARGUMENT);
  CHECK(detsim_world_frame(NULL) == 0);
  detsim_world_destroy(NULL);
  detsim_world_destroy(world);
}

static void queries_hit_where_the_geometry_says(void) {
  detsim_world* world = ball_world();
  detsim_vec3 origin = {fx("5"), fx("10"), 0};
  detsim_vec3 down = {0, fx("-20"), 0};
  detsim_hit hit;
  int found = 0;
  CHECK(detsim_world_raycast(world, origin, down, &hit, &found) == DETSIM_OK && found == 1);
  CHECK(hit.body == 1 && hit.fraction == DETSIM_FIXED_ONE / 2);
  CHECK(hit.normal.y == DETSIM_FIXED_ONE);
  /* A 0.25 m ball cast down 10 m from 5 m stops 4.75 m on, short by at most the slop (2^-12). */
  detsim_shape ball = {DETSIM_SHAPE_SPHERE, DETSIM_FIXED_ONE / 4, 0, {0, 0, 0}};
  detsim_quat identity = {DETSIM_FIXED_ONE, 0, 0, 0};
  detsim_vec3 from = {fx("5"), fx("5"), 0};
  detsim_vec3 cast = {0, fx("-10"), 0};
  CHECK(detsim_world_shape_cast(world, &ball, from, identity, cast, &hit, &found) == DETSIM_OK);
  CHECK(found == 1 && hit.body == 1);
  const detsim_fixed travelled =
      (detsim_fixed)(detsim_fixed_to_double(hit.fraction) * 10.0 * 4294967296.0);
  CHECK(travelled <= fx("4.75") && travelled >= fx("4.75") - (DETSIM_FIXED_ONE >> 12) - 4096);
  /* Cast sideways at the height of nothing: no hit. */
  detsim_vec3 high = {0, fx("50"), 0};
  detsim_vec3 sideways = {fx("10"), 0, 0};
  CHECK(detsim_world_shape_cast(world, &ball, high, identity, sideways, &hit, &found) == DETSIM_OK);
  CHECK(found == 0);
  detsim_world_destroy(world);
}

/* ---- A rollback match of two sessions over a bad simulated network ---- */

/* The game: a world of two balls on a plane; each player's first input byte kicks its ball. */
typedef struct ball_game {
  detsim_world* world;
  int resimulated; /* frames advanced again after a rollback */
} ball_game;

static uint64_t game_save(void* context, uint8_t** buffer, size_t* size) {
  ball_game* game = context;
  size_t needed = 0;
  detsim_world_save(game->world, NULL, 0, &needed);
  *buffer = malloc(needed);
  CHECK(*buffer != NULL);
  CHECK(detsim_world_save(game->world, *buffer, needed, size) == DETSIM_OK);
  uint64_t hash = 0;
  detsim_world_hash(game->world, &hash);
  return hash;
}

static void game_free(void* context, uint8_t* buffer) {
  (void)context;
  free(buffer);
}

static void game_load(void* context, const uint8_t* buffer, size_t size) {
  ball_game* game = context;
  CHECK(detsim_world_restore(game->world, buffer, size) == DETSIM_OK);
}

static void game_advance(void* context, uint64_t frame, const uint8_t* inputs, uint32_t players,
                         uint32_t input_size, const uint8_t* status, int resimulating) {
  ball_game* game = context;
  (void)frame;
  (void)status;
  for (uint32_t p = 0; p < players; ++p) {
    const uint8_t kick = inputs[p * input_size];
    if (kick != 0) {
      detsim_vec3 impulse = {(detsim_fixed)(kick & 7) * DETSIM_FIXED_ONE * 100,
                             (kick & 8) ? 2000 * DETSIM_FIXED_ONE : 0, 0};
      CHECK(detsim_body_apply_impulse(game->world, 2 + p, impulse) == DETSIM_OK);
    }
  }
  game->resimulated += resimulating;
  CHECK(detsim_world_step(game->world) == DETSIM_OK);
}

static detsim_world* two_ball_world(void) {
  detsim_world* world = ball_world();
  detsim_body_def ball;
  detsim_body_def_init(&ball);
  ball.position.x = fx("3");
  ball.position.y = fx("1");
  uint32_t id = 0;
  CHECK(detsim_body_create(world, &ball, &id) == DETSIM_OK && id == 3);
  return world;
}

/* Player p's input at frame f: a kick now and then, different per player. */
static uint8_t input_of(uint64_t frame, uint32_t player) {
  const uint64_t mix = (frame + 1) * 2654435761U + player * 40503U;
  return (mix >> 7) % 11 == 0 ? (uint8_t)((mix >> 3) & 15) : 0;
}

static void a_rollback_match_ends_with_equal_confirmed_hashes(void) {
  detsim_link link = {30000, 10000, 50000, 10000, 20000}; /* 30+-10 ms, 5 % loss */
  detsim_network* network = NULL;
  CHECK(detsim_network_create(2, 7, &link, &network) == DETSIM_OK);
  ball_game games[2];
  detsim_game callbacks[2];
  detsim_session* sessions[2] = {NULL, NULL};
  for (uint32_t p = 0; p < 2; ++p) {
    games[p].world = two_ball_world();
    games[p].resimulated = 0;
    callbacks[p].context = &games[p];
    callbacks[p].save = game_save;
    callbacks[p].free_buffer = game_free;
    callbacks[p].load = game_load;
    callbacks[p].advance = game_advance;
    detsim_session_config config;
    detsim_session_config_init(&config);
    config.local_player = p;
    config.fingerprint = 0xC0FFEE;
    CHECK(detsim_session_create(&config, &callbacks[p], network, &sessions[p]) == DETSIM_OK);
  }
  /* 20 s of play at 60 Hz on a virtual clock, then 1 s more of polling for the last inputs. */
  uint32_t advanced = 0;
  for (uint64_t tick = 0; tick < 1260; ++tick) {
    const uint64_t now = tick * 16667;
    detsim_network_advance_to(network, now);
    for (uint32_t p = 0; p < 2; ++p) {
      CHECK(detsim_session_poll(sessions[p], now) == DETSIM_OK);
      if (tick >= 1200) continue;
      uint8_t input[4] = {input_of(detsim_session_current_frame(sessions[p]), p), 0, 0, 0};
      uint32_t what = 99;
      CHECK(detsim_session_advance_frame(sessions[p], input, sizeof input, &what) == DETSIM_OK);
      advanced += what == DETSIM_ADVANCED;
    }
  }
  const uint64_t confirmed_a = detsim_session_confirmed_frame(sessions[0]);
  const uint64_t confirmed_b = detsim_session_confirmed_frame(sessions[1]);
  const uint64_t confirmed = confirmed_a < confirmed_b ? confirmed_a : confirmed_b;
  CHECK(advanced > 2000);
  CHECK(confirmed > 1000);
  CHECK(games[0].resimulated + games[1].resimulated > 0); /* the network made it roll back */
  uint64_t compared = 0;
  /* The last frames confirmed when play stopped were never simulated past (their hashes are of
   * states not reached yet): compare the 1000 before them. */
  for (uint64_t frame = confirmed - 1010; frame < confirmed - 10; ++frame) {
    uint64_t ha = 0;
    uint64_t hb = 1;
    CHECK(detsim_session_confirmed_hash(sessions[0], frame, &ha) == DETSIM_OK);
    CHECK(detsim_session_confirmed_hash(sessions[1], frame, &hb) == DETSIM_OK);
    CHECK(ha == hb);
    compared += ha == hb;
  }
  CHECK(compared == 1000);
  uint64_t unused = 0;
  CHECK(detsim_session_confirmed_hash(sessions[0], confirmed + 5000, &unused) ==
        DETSIM_INVALID_ARGUMENT);
  uint8_t wrong[3] = {0, 0, 0};
  uint32_t what = 0;
  CHECK(detsim_session_advance_frame(sessions[0], wrong, sizeof wrong, &what) ==
        DETSIM_INVALID_ARGUMENT);
  CHECK(strlen(detsim_last_error()) > 0);
  for (uint32_t p = 0; p < 2; ++p) {
    detsim_session_destroy(sessions[p]);
    detsim_world_destroy(games[p].world);
  }
  detsim_network_destroy(network);
}

/* ---- The same match over UDP on this machine, and over the game's own transport ---- */

/* Plays `ticks` 60 Hz ticks of two sessions on a virtual clock (the last 60 without new input),
 * then checks that both confirmed at least `min_confirmed` frames and hashed the 300 before the
 * last 10 alike. */
static void play_and_compare(detsim_session* sessions[2], uint64_t ticks, uint64_t min_confirmed) {
  for (uint64_t tick = 0; tick < ticks; ++tick) {
    const uint64_t now = tick * 16667;
    for (uint32_t p = 0; p < 2; ++p) {
      CHECK(detsim_session_poll(sessions[p], now) == DETSIM_OK);
      if (tick + 60 >= ticks) continue;
      uint8_t input[4] = {input_of(detsim_session_current_frame(sessions[p]), p), 0, 0, 0};
      uint32_t what = 99;
      CHECK(detsim_session_advance_frame(sessions[p], input, sizeof input, &what) == DETSIM_OK);
    }
  }
  const uint64_t confirmed_a = detsim_session_confirmed_frame(sessions[0]);
  const uint64_t confirmed_b = detsim_session_confirmed_frame(sessions[1]);
  const uint64_t confirmed = confirmed_a < confirmed_b ? confirmed_a : confirmed_b;
  CHECK(confirmed >= min_confirmed);
  if (confirmed < 310) return;
  uint64_t equal = 0;
  for (uint64_t frame = confirmed - 310; frame < confirmed - 10; ++frame) {
    uint64_t ha = 0;
    uint64_t hb = 1;
    CHECK(detsim_session_confirmed_hash(sessions[0], frame, &ha) == DETSIM_OK);
    CHECK(detsim_session_confirmed_hash(sessions[1], frame, &hb) == DETSIM_OK);
    equal += ha == hb;
  }
  CHECK(equal == 300);
}

/* Two players' games and their sessions, player p's over transports[p]. */
static void start_match(ball_game games[2], detsim_game callbacks[2],
                        detsim_transport* transports[2], detsim_session* sessions[2]) {
  for (uint32_t p = 0; p < 2; ++p) {
    games[p].world = two_ball_world();
    games[p].resimulated = 0;
    callbacks[p].context = &games[p];
    callbacks[p].save = game_save;
    callbacks[p].free_buffer = game_free;
    callbacks[p].load = game_load;
    callbacks[p].advance = game_advance;
    detsim_session_config config;
    detsim_session_config_init(&config);
    config.local_player = p;
    config.fingerprint = 0xC0FFEE;
    CHECK(detsim_session_create_on(&config, &callbacks[p], transports[p], &sessions[p]) ==
          DETSIM_OK);
  }
}

static void a_match_over_udp_on_this_machine_ends_with_equal_hashes(void) {
  detsim_transport* udp[2] = {NULL, NULL};
  uint16_t ports[2] = {0, 0};
  for (uint32_t p = 0; p < 2; ++p) {
    CHECK(detsim_udp_open("127.0.0.1:0", &udp[p]) == DETSIM_OK);
    CHECK(detsim_udp_local_port(udp[p], &ports[p]) == DETSIM_OK && ports[p] != 0);
  }
  for (uint32_t p = 0; p < 2; ++p) {
    char address[32];
    snprintf(address, sizeof address, "127.0.0.1:%u", (unsigned)ports[1 - p]);
    CHECK(detsim_udp_add_peer(udp[p], 1 - p, address) == DETSIM_OK);
  }
  ball_game games[2];
  detsim_game callbacks[2];
  detsim_session* sessions[2] = {NULL, NULL};
  start_match(games, callbacks, udp, sessions);
  play_and_compare(sessions, 660, 500);
  /* Refusals: a bad address, a second peer at the same player, a UDP call on another transport. */
  detsim_transport* bad = NULL;
  CHECK(detsim_udp_open("127.0.0.1:99999", &bad) == DETSIM_INVALID_ARGUMENT && bad == NULL);
  CHECK(strstr(detsim_last_error(), "99999") != NULL);
  CHECK(detsim_udp_add_peer(udp[0], 1, "127.0.0.1:9") == DETSIM_INVALID_ARGUMENT);
  for (uint32_t p = 0; p < 2; ++p) {
    detsim_session_destroy(sessions[p]);
    detsim_transport_destroy(udp[p]);
    detsim_world_destroy(games[p].world);
  }
}

/* The game's own network: each player's datagrams are delivered to the other player's
 * transport, one in ten dropped. */
typedef struct wire {
  detsim_transport* transports[2];
  uint32_t sent;
  uint32_t dropped;
} wire;
typedef struct wire_end {
  wire* wire;
  uint32_t player;
} wire_end;

static void wire_send(void* context, uint32_t player, const uint8_t* bytes, size_t size) {
  wire_end* end = context;
  CHECK(player == 1 - end->player);
  CHECK(size <= DETSIM_MAX_DATAGRAM);
  if (++end->wire->sent % 10 == 0) {
    ++end->wire->dropped;
    return;
  }
  CHECK(detsim_transport_deliver(end->wire->transports[player], end->player, bytes, size) ==
        DETSIM_OK);
}

static void a_match_over_the_games_own_transport_ends_with_equal_hashes(void) {
  wire w = {{NULL, NULL}, 0, 0};
  wire_end ends[2] = {{&w, 0}, {&w, 1}};
  for (uint32_t p = 0; p < 2; ++p)
    CHECK(detsim_transport_create(wire_send, &ends[p], &w.transports[p]) == DETSIM_OK);
  ball_game games[2];
  detsim_game callbacks[2];
  detsim_session* sessions[2] = {NULL, NULL};
  start_match(games, callbacks, w.transports, sessions);
  play_and_compare(sessions, 660, 500);
  CHECK(w.dropped > 0);
  /* Refusals: an oversized datagram, a UDP call on a callback transport, no send function. */
  static uint8_t big[DETSIM_MAX_DATAGRAM + 1];
  CHECK(detsim_transport_deliver(w.transports[0], 1, big, sizeof big) == DETSIM_INVALID_ARGUMENT);
  CHECK(strstr(detsim_last_error(), "1201") != NULL);
  CHECK(detsim_udp_add_peer(w.transports[0], 1, "127.0.0.1:7000") == DETSIM_INVALID_ARGUMENT);
  detsim_transport* none = NULL;
  CHECK(detsim_transport_create(NULL, NULL, &none) == DETSIM_INVALID_ARGUMENT && none == NULL);
  for (uint32_t p = 0; p < 2; ++p) {
    detsim_session_destroy(sessions[p]);
    detsim_transport_destroy(w.transports[p]);
    detsim_world_destroy(games[p].world);
  }
}

int main(void) {
  numbers();
  a_ball_comes_to_rest_on_the_plane();
  a_saved_world_restores_and_steps_alike();
  refusals_name_the_field_and_change_nothing();
  queries_hit_where_the_geometry_says();
  a_rollback_match_ends_with_equal_confirmed_hashes();
  a_match_over_udp_on_this_machine_ends_with_equal_hashes();
  a_match_over_the_games_own_transport_ends_with_equal_hashes();
  if (failures > 0) {
    fprintf(stderr, "%d check(s) failed\n", failures);
    return 1;
  }
  printf("c_api_test: every check holds\n");
  return 0;
}
