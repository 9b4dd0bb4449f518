#!/usr/bin/env python3
"""The C API from Python's ctypes, as a binding would use it (libdetsim_c.so): a ball dropped on a
plane rests a radius above it, and two rollback sessions, each driving a world through Python
callbacks over a lossy, jittery simulated network, agree on the hashes of 1000 confirmed frames.

Usage: c_api_test.py PATH/TO/libdetsim_c.so   (exit 0 when every check holds)
"""
import ctypes as C
import sys

ONE = 1 << 32
failures = []


def check(condition, what):
    if not condition:
        failures.append(what)
        print("failed:", what, file=sys.stderr)


class Vec3(C.Structure):
    _fields_ = [("x", C.c_int64), ("y", C.c_int64), ("z", C.c_int64)]


class Quat(C.Structure):
    _fields_ = [("w", C.c_int64), ("x", C.c_int64), ("y", C.c_int64), ("z", C.c_int64)]


class Shape(C.Structure):
    _fields_ = [("type", C.c_uint32), ("radius", C.c_int64), ("half_height", C.c_int64),
                ("half_extents", Vec3)]


class BodyDef(C.Structure):
    _fields_ = [("type", C.c_uint32), ("shape", Shape), ("position", Vec3),
                ("orientation", Quat), ("linear_velocity", Vec3), ("angular_velocity", Vec3),
                ("mass", C.c_int64), ("density", C.c_int64), ("friction", C.c_int64),
                ("restitution", C.c_int64), ("layer", C.c_uint32), ("mask", C.c_uint32),
                ("user_data", C.c_uint64)]


class BodyState(C.Structure):
    _fields_ = [("id", C.c_uint32), ("type", C.c_uint32), ("position", Vec3),
                ("orientation", Quat), ("linear_velocity", Vec3), ("angular_velocity", Vec3),
                ("mass", C.c_int64), ("awake", C.c_int), ("user_data", C.c_uint64)]


SAVE = C.CFUNCTYPE(C.c_uint64, C.c_void_p, C.POINTER(C.POINTER(C.c_uint8)),
                   C.POINTER(C.c_size_t))
FREE = C.CFUNCTYPE(None, C.c_void_p, C.POINTER(C.c_uint8))
LOAD = C.CFUNCTYPE(None, C.c_void_p, C.POINTER(C.c_uint8), C.c_size_t)
ADVANCE = C.CFUNCTYPE(None, C.c_void_p, C.c_uint64, C.POINTER(C.c_uint8), C.c_uint32,
                      C.c_uint32, C.POINTER(C.c_uint8), C.c_int)


class Game(C.Structure):
    _fields_ = [("context", C.c_void_p), ("save", SAVE), ("free_buffer", FREE), ("load", LOAD),
                ("advance", ADVANCE)]


class Link(C.Structure):
    _fields_ = [("latency_us", C.c_uint32), ("jitter_us", C.c_uint32), ("loss_ppm", C.c_uint32),
                ("duplicate_ppm", C.c_uint32), ("reorder_ppm", C.c_uint32)]


class SessionConfig(C.Structure):
    _fields_ = [("mode", C.c_uint32), ("players", C.c_uint32), ("local_player", C.c_uint32),
                ("input_size", C.c_uint32), ("input_delay", C.c_uint32),
                ("max_prediction", C.c_uint32), ("fingerprint", C.c_uint64)]


def load_library(path):
    lib = C.CDLL(path)
    lib.detsim_last_error.restype = C.c_char_p
    lib.detsim_world_create.argtypes = [C.c_void_p, C.POINTER(C.c_void_p)]
    lib.detsim_world_destroy.argtypes = [C.c_void_p]
    lib.detsim_world_step.argtypes = [C.c_void_p]
    lib.detsim_world_save.argtypes = [C.c_void_p, C.c_void_p, C.c_size_t, C.POINTER(C.c_size_t)]
    lib.detsim_world_restore.argtypes = [C.c_void_p, C.c_void_p, C.c_size_t]
    lib.detsim_world_hash.argtypes = [C.c_void_p, C.POINTER(C.c_uint64)]
    lib.detsim_body_def_init.argtypes = [C.POINTER(BodyDef)]
    lib.detsim_body_create.argtypes = [C.c_void_p, C.POINTER(BodyDef), C.POINTER(C.c_uint32)]
    lib.detsim_body_get.argtypes = [C.c_void_p, C.c_uint32, C.POINTER(BodyState)]
    lib.detsim_body_apply_impulse.argtypes = [C.c_void_p, C.c_uint32, Vec3]
    lib.detsim_network_create.argtypes = [C.c_uint32, C.c_uint64, C.POINTER(Link),
                                          C.POINTER(C.c_void_p)]
    lib.detsim_network_destroy.argtypes = [C.c_void_p]
    lib.detsim_network_advance_to.argtypes = [C.c_void_p, C.c_uint64]
    lib.detsim_session_config_init.argtypes = [C.POINTER(SessionConfig)]
    lib.detsim_session_create.argtypes = [C.POINTER(SessionConfig), C.POINTER(Game), C.c_void_p,
                                          C.POINTER(C.c_void_p)]
    lib.detsim_session_destroy.argtypes = [C.c_void_p]
    lib.detsim_session_poll.argtypes = [C.c_void_p, C.c_uint64]
    lib.detsim_session_advance_frame.argtypes = [C.c_void_p, C.c_void_p, C.c_size_t,
                                                 C.POINTER(C.c_uint32)]
    lib.detsim_session_current_frame.argtypes = [C.c_void_p]
    lib.detsim_session_current_frame.restype = C.c_uint64
    lib.detsim_session_confirmed_frame.argtypes = [C.c_void_p]
    lib.detsim_session_confirmed_frame.restype = C.c_uint64
    lib.detsim_session_confirmed_hash.argtypes = [C.c_void_p, C.c_uint64, C.POINTER(C.c_uint64)]
    return lib


def ball_world(lib, balls):
    """A static plane (ID 1) and `balls` 0.5 m balls (IDs 2, 3, ...) 1 m up, 3 m apart."""
    world = C.c_void_p()
    check(lib.detsim_world_create(None, C.byref(world)) == 0, "world created")
    ground = BodyDef()
    lib.detsim_body_def_init(C.byref(ground))
    ground.type = 0
    ground.shape.type = 4
    body = C.c_uint32()
    check(lib.detsim_body_create(world, C.byref(ground), C.byref(body)) == 0, "ground created")
    for k in range(balls):
        ball = BodyDef()
        lib.detsim_body_def_init(C.byref(ball))
        ball.position.x = 3 * k * ONE
        ball.position.y = ONE
        check(lib.detsim_body_create(world, C.byref(ball), C.byref(body)) == 0, "ball created")
    return world


def a_ball_comes_to_rest(lib):
    world = ball_world(lib, 1)
    for _ in range(120):
        lib.detsim_world_step(world)
    state = BodyState()
    check(lib.detsim_body_get(world, 2, C.byref(state)) == 0, "ball read")
    check(abs(state.position.y - ONE // 2) < ONE // 50, "the ball rests a radius up")
    check(lib.detsim_body_get(world, 42, C.byref(state)) == 1, "an unknown ID is refused")
    check(b"42" in lib.detsim_last_error(), "the message names the ID")
    lib.detsim_world_destroy(world)


def input_of(frame, player):
    mix = (frame + 1) * 2654435761 + player * 40503
    return ((mix >> 3) & 15) if (mix >> 7) % 11 == 0 else 0


def a_rollback_match_from_python(lib):
    link = Link(30000, 10000, 50000, 10000, 20000)
    network = C.c_void_p()
    check(lib.detsim_network_create(2, 7, C.byref(link), C.byref(network)) == 0, "network")
    worlds = [ball_world(lib, 2) for _ in range(2)]
    resimulated = [0, 0]
    buffers = {}

    def make_game(p):
        world = worlds[p]

        def save(_, buffer, size):
            needed = C.c_size_t()
            lib.detsim_world_save(world, None, 0, C.byref(needed))
            data = (C.c_uint8 * needed.value)()
            lib.detsim_world_save(world, data, needed.value, C.byref(needed))
            buffers[C.addressof(data)] = data  # kept alive until free_buffer
            buffer[0] = C.cast(data, C.POINTER(C.c_uint8))
            size[0] = needed.value
            digest = C.c_uint64()
            lib.detsim_world_hash(world, C.byref(digest))
            return digest.value

        def free_buffer(_, buffer):
            del buffers[C.addressof(buffer.contents)]

        def load(_, buffer, size):
            check(lib.detsim_world_restore(world, buffer, size) == 0, "load")

        def advance(_, frame, inputs, players, input_size, status, resimulating):
            for q in range(players):
                kick = inputs[q * input_size]
                if kick:
                    impulse = Vec3((kick & 7) * ONE * 100, 2000 * ONE if kick & 8 else 0, 0)
                    lib.detsim_body_apply_impulse(world, 2 + q, impulse)
            resimulated[p] += resimulating
            lib.detsim_world_step(world)

        return (SAVE(save), FREE(free_buffer), LOAD(load), ADVANCE(advance))

    callbacks = [make_game(p) for p in range(2)]  # kept alive for the session's lifetime
    sessions = []
    for p in range(2):
        game = Game(None, *callbacks[p])
        config = SessionConfig()
        lib.detsim_session_config_init(C.byref(config))
        config.local_player = p
        config.fingerprint = 0xC0FFEE
        session = C.c_void_p()
        check(lib.detsim_session_create(C.byref(config), C.byref(game), network,
                                        C.byref(session)) == 0, "session created")
        sessions.append(session)
    advanced = 0
    for tick in range(1260):
        now = tick * 16667
        lib.detsim_network_advance_to(network, now)
        for p in range(2):
            lib.detsim_session_poll(sessions[p], now)
            if tick >= 1200:
                continue
            frame = lib.detsim_session_current_frame(sessions[p])
            data = (C.c_uint8 * 4)(input_of(frame, p), 0, 0, 0)
            what = C.c_uint32(99)
            check(lib.detsim_session_advance_frame(sessions[p], data, 4, C.byref(what)) == 0,
                  "advance")
            advanced += what.value == 0
    confirmed = min(lib.detsim_session_confirmed_frame(s) for s in sessions)
    check(advanced > 2000, "frames advanced: %d" % advanced)
    check(confirmed > 1000, "confirmed frames: %d" % confirmed)
    check(sum(resimulated) > 0, "the network made the sessions roll back")
    equal = 0
    for frame in range(confirmed - 1010, confirmed - 10):
        a, b = C.c_uint64(0), C.c_uint64(1)
        lib.detsim_session_confirmed_hash(sessions[0], frame, C.byref(a))
        lib.detsim_session_confirmed_hash(sessions[1], frame, C.byref(b))
        equal += a.value == b.value
    check(equal == 1000, "confirmed hashes equal on both sides: %d of 1000" % equal)
    for p in range(2):
        lib.detsim_session_destroy(sessions[p])
        lib.detsim_world_destroy(worlds[p])
    lib.detsim_network_destroy(network)
    check(not buffers, "every saved buffer was freed")


def main():
    lib = load_library(sys.argv[1])
    a_ball_comes_to_rest(lib)
    a_rollback_match_from_python(lib)
    if failures:
        print("%d check(s) failed" % len(failures), file=sys.stderr)
        return 1
    print("c_api_test.py: every check holds")
    return 0


if __name__ == "__main__":
    sys.exit(main())
