/* The C API from C11 (<detsim/detsim.h>): a ball dropped on a plane comes to rest on it, a saved
 * world restores into a second one that then steps to the same hashes, refusals name the field
 * and change nothing, NULL pointers are refused, and queries hit where the geometry says. Exit
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

int main(void) {
  numbers();
  a_ball_comes_to_rest_on_the_plane();
  a_saved_world_restores_and_steps_alike();
  refusals_name_the_field_and_change_nothing();
  queries_hit_where_the_geometry_says();
  if (failures > 0) {
    fprintf(stderr, "%d check(s) failed\n", failures);
    return 1;
  }
  printf("c_api_test: every check holds\n");
  return 0;
}
