#!/usr/bin/env python3
"""Generates the tables and coefficients of fixed/src/exp_log.cpp and checks their error budgets.

Everything here mirrors the integer evaluation in exp_log.cpp bit for bit (the `emulate_*`
functions), so the sampled errors below are the errors of the C++ code, not of an idealisation.

exp and exp2, 2^k T e^h (exp_magnitude):
    T = 2^(j/256) from kExp2Table (Q1.63, rounded to nearest) and h = h71 / 2^71 in
    [0, (ln2/256)(1 + 2^-12)). exp2 takes j = F >> 56 and h71 = mulhi(F << 8, kLn2Q63) from the
    fraction F / 2^64; exp takes n = (raw kExpIndexScale - 2^36) >> 49 (floor(x 256/ln2) or one
    less), j = n mod 256, k = n >> 8, h71 = raw 2^39 - n kLn2Q63 modulo 2^64.
    e^h - 1 = h + h^2/2 + h^3 (c3 + c4 h), (c3, c4) fitted (mpmath.chebyfit) to
    (e^h - 1 - h - h^2/2) / h^3 and stored scaled by 2^34 (kExpCubic). With S = mulhi(H, H),
    H40 = H >> 31: inner = c3 + (H40 c4 >> 40), W = (H40 inner) >> 31,
    p = H + (S >> 8) + ((S >> 29) W >> 21), M = T + ((mulhi(T, p) + 64) >> 7) (may pass 2^64).

ln and log2 of m in [1, 2) (fast path, 64-bit):
    j = top 8 fraction bits of m; r = kLogRecip[j] / 2^16 = ceil(2^16 / (1 + j/256)) / 2^16, so
    that U = (m >> 7) r modulo 2^64 (m as Q1.63) is u 2^72 with u = m' r - 1 in [0, 2^-8), m' the
    57-bit truncation of m. ln(1 + u) = u - u^2/2 + u^3 (c3 - c4 u), fitted like exp's and stored
    as magnitudes scaled by 2^34 (kLogCubic). With S = mulhi(U, U), U39 = U >> 33:
    inner = c3 - (U39 c4 >> 39), W = (U39 inner) >> 33,
    P = U - (S >> 9) + ((S >> 31) W >> 17) = ln(1 + u) 2^72.
    ln x 2^58 = kExponentLn2[e + 32] + kLnRecip[j] + (P >> 14); log2 x 2^58 = e 2^58 +
    kLog2Recip[j] + (mulhi(P, kLog2E.hi) >> 13); tables at 2^58, rounded to nearest.

log2 in extended precision (for pow: |error| < 2^-96 absolute):
    the first reduction as above with 128 intervals: j = top 7 fraction bits of m,
    r1 = kRecip1[j] / 2^16 = ceil(2^16 / (1 + j/128)) / 2^16, u1 = m r1 - 1 in [0, 2^-7) exact
    (a 64 x 17-bit product) and -log2(r1) from kLog2Recip1 (Q0.128); then a second exact
    reduction: j2 = floor(u1 * 2^14), r2 = kRecip2[j2] / 2^24 = ceil(2^24 / (1 + j2 / 2^14)) / 2^24,
    u2 = (1 + u1) r2 - 1 in [0, 2^-14 + 2^-24), exact in 103 fraction bits.
    log2(1 + u2) = u2/ln2 - u2^2/(2 ln2) + u2^3 (c3 - u2 (c4 - u2 (c5 - u2 c6))) (Taylor;
    truncation < 2^-100): the first two terms in 128-bit arithmetic, the tail in 64-bit.

Usage: python3 scripts/gen/explog_tables.py   (prints the C++ block of exp_log.cpp)
"""
import random

import mpmath

mpmath.mp.prec = 300
M64 = (1 << 64) - 1
TWO = mpmath.mpf(2)

INDEX_BITS = 7
TABLE_SIZE = 1 << INDEX_BITS
RECIP1_BITS = 16
RECIP2_BITS = 24
STAGE2_BITS = 14  # j2 = floor(u1 * 2^14)

EXP2_BITS = 8  # 2^(j/256)
EXP2_SIZE = 1 << EXP2_BITS
LOG_BITS = 8  # the fast logarithms' table index: u < 2^-8
LOG_SIZE = 1 << LOG_BITS
CUBIC_SCALE = 34  # kExpCubic and kLogCubic are scaled by 2^34


def mulhi(a, b):
    assert 0 <= a <= M64 and 0 <= b <= M64
    return (a * b) >> 64


def nint(x):
    return int(mpmath.nint(x))


def fit(f, h, degree):
    """Near-minimax coefficients (constant first) of f on [0, h] via Chebyshev interpolation."""
    coeffs, _ = mpmath.chebyfit(f, [0, h], degree + 1, error=True)
    return list(reversed(coeffs))


# ---- exp and exp2 --------------------------------------------------------------------------------

EXP_H_MAX = mpmath.ln(2) / EXP2_SIZE * (1 + TWO**-12)  # exp_magnitude's domain of h


def exp_tables():
    table = [nint(TWO ** (mpmath.mpf(j) / EXP2_SIZE) * TWO**63) for j in range(EXP2_SIZE)]
    assert table[0] == 1 << 63 and all(t <= M64 for t in table)
    cubic = fit(lambda h: (mpmath.expm1(h) - h - h * h / 2) / h**3 if h != 0 else mpmath.mpf(1) / 6,
                EXP_H_MAX, 1)
    assert all(c > 0 for c in cubic)
    cubic = [nint(c * TWO**CUBIC_SCALE) for c in cubic]
    ln2_q63 = nint(mpmath.ln(2) * TWO**63)
    index_scale = nint(TWO**25 / mpmath.ln(2))
    return table, cubic, ln2_q63, index_scale


def emulate_exp_magnitude(cubic, t, h71):
    """The mantissa M = T e^h as an integer (the C++ keeps M / 2 with k + 1 when it passes 2^64)."""
    assert 0 <= h71 < TWO**62.6
    s = mulhi(h71, h71)
    h40 = h71 >> 31
    inner = cubic[0] + ((h40 * cubic[1]) >> 40)
    assert h40 * inner <= M64
    w = (h40 * inner) >> 31
    assert (s >> 29) * w <= M64
    p = h71 + (s >> 8) + (((s >> 29) * w) >> 21)
    return t + ((mulhi(t, p) + 64) >> 7)


def emulate_exp(table, cubic, ln2_q63, index_scale, raw):
    """(k, M) with e^(raw / 2^32) ~ 2^k M / 2^63, for -24 < raw / 2^32 < 22."""
    n = (raw * index_scale - (1 << 36)) >> 49
    h71 = (raw << 39) - n * ln2_q63
    assert 0 <= h71 <= M64  # the C++ forms it modulo 2^64
    return n >> 8, emulate_exp_magnitude(cubic, table[n & 255], h71)


def emulate_exp2(table, cubic, ln2_q63, f):
    return emulate_exp_magnitude(cubic, table[f >> 56], mulhi((f << 8) & M64, ln2_q63))


def exp_index_margin():
    """min |raw 2^-24 / ln2 - n| over integers n and 0 < |raw| < 2^36.6 (the continued fraction of
    2^-24 / ln2: the last convergent denominator in range gives the minimum)."""
    beta = TWO**-24 / mpmath.ln(2)
    x, (p0, q0, p1, q1) = beta, (0, 1, 1, 0)
    best = mpmath.mpf(1)
    for _ in range(100):
        a = int(mpmath.floor(x))
        p0, q0, p1, q1 = p1, q1, a * p1 + p0, a * q1 + q0
        if q1 > 24 * 2**32:
            break
        best = min(best, abs(q1 * beta - p1))
        x = 1 / (x - a)
    return best


def check_exp(table, cubic, ln2_q63, index_scale, rng):
    """Relative errors of exp's and exp2's mantissas."""
    worst_exp = mpmath.mpf(0)
    raws = [0, 1, -1, 22 * 2**32 - 1, -24 * 2**32 + 1]
    raws += [rng.randrange(-24 * 2**32 + 1, 22 * 2**32) for _ in range(20000)]
    for n in range(-8870, 8130, 3):  # around the index boundaries
        centre = nint(n * mpmath.ln(2) / EXP2_SIZE * TWO**32)
        raws += [centre - 1, centre, centre + 1]
    for raw in raws:
        if not -24 * 2**32 < raw < 22 * 2**32:
            continue
        k, m = emulate_exp(table, cubic, ln2_q63, index_scale, raw)
        exact = mpmath.exp(mpmath.mpf(raw) / TWO**32)
        worst_exp = max(worst_exp, abs(m * TWO ** (k - 63) / exact - 1))
    worst_exp2 = mpmath.mpf(0)
    samples = []
    low = 64 - EXP2_BITS
    for j in range(EXP2_SIZE):
        base = j << low
        samples += [base, base + 1, base + (1 << (low - 1)), base + (1 << low) - 1]
        samples += [base + rng.getrandbits(low) for _ in range(20)]
    samples += [rng.getrandbits(64) for _ in range(4000)]
    samples += [rng.getrandbits(32) << 32 for _ in range(2000)]
    for f in samples:
        m = emulate_exp2(table, cubic, ln2_q63, f)
        exact = TWO ** (mpmath.mpf(f) / TWO**64) * TWO**63
        worst_exp2 = max(worst_exp2, abs(m / exact - 1))
    assert emulate_exp2(table, cubic, ln2_q63, 0) == 1 << 63
    return worst_exp, worst_exp2


def fit_error(f, h, coefficients, power):
    """max |poly - f| h^power over [0, h], on a fine grid (coefficients constant first)."""
    worst = mpmath.mpf(0)
    for x in mpmath.linspace(0, h, 4001):
        worst = max(worst, abs(mpmath.polyval(list(reversed(coefficients)), x) - f(x)) * x**power)
    return worst


# ---- logarithm tables ---------------------------------------------------------------------------

def recip_tables():
    recip1 = []
    for j in range(TABLE_SIZE):
        a = mpmath.mpf(TABLE_SIZE + j) / TABLE_SIZE
        r = -(-(1 << (RECIP1_BITS + INDEX_BITS)) // (TABLE_SIZE + j))  # ceil(2^16 / a)
        recip1.append(r)
        # u = m r - 1 over m in [a, a + 2^-7): exact rational bounds.
        lo = (TABLE_SIZE + j) * r - (TABLE_SIZE << RECIP1_BITS)
        hi = (TABLE_SIZE + j + 1) * r - (TABLE_SIZE << RECIP1_BITS)
        assert lo >= 0
        assert hi <= 1 << RECIP1_BITS, (j, hi)  # u < 2^-7 (the sup is not attained)
    assert recip1[0] == 1 << RECIP1_BITS
    recip2 = []
    for k in range(TABLE_SIZE):
        den = (1 << STAGE2_BITS) + k
        r = -(-(1 << (RECIP2_BITS + STAGE2_BITS)) // den)
        recip2.append(r)
        lo = den * r - (1 << (RECIP2_BITS + STAGE2_BITS))
        assert lo >= 0
    assert recip2[0] == 1 << RECIP2_BITS
    return recip1, recip2


def stage2_bound(recip2):
    """sup of u2 = (1 + u1) r2 - 1 over u1 in [k 2^-14, (k + 1) 2^-14), in units of 2^-14."""
    worst = mpmath.mpf(0)
    for k, r in enumerate(recip2):
        sup = mpmath.mpf((1 << STAGE2_BITS) + k + 1) * r / TWO ** (RECIP2_BITS + STAGE2_BITS) - 1
        worst = max(worst, sup)
    return worst


def log_tables(recip1, recip2):
    log2_r1 = [nint(-mpmath.log(mpmath.mpf(r) / TWO**RECIP1_BITS, 2) * TWO**128) for r in recip1]
    log2_r2 = [nint(-mpmath.log(mpmath.mpf(r) / TWO**RECIP2_BITS, 2) * TWO**128) for r in recip2]
    assert log2_r1[0] == 0 and log2_r2[0] == 0
    assert all(0 <= v < 1 << 128 for v in log2_r1 + log2_r2)
    return log2_r1, log2_r2


def fast_log_tables():
    recip = []
    for j in range(LOG_SIZE):
        r = -(-(1 << (RECIP1_BITS + LOG_BITS)) // (LOG_SIZE + j))  # ceil(2^16 / (1 + j/256))
        hi = (LOG_SIZE + j + 1) * r - (LOG_SIZE << RECIP1_BITS)
        assert hi <= 1 << RECIP1_BITS, (j, hi)  # u < 2^-8 (the sup is not attained)
        recip.append(r)
    ln_r = [nint(-mpmath.log(mpmath.mpf(r) / TWO**RECIP1_BITS) * TWO**58) for r in recip]
    log2_r = [nint(-mpmath.log(mpmath.mpf(r) / TWO**RECIP1_BITS, 2) * TWO**58) for r in recip]
    assert ln_r[0] == 0 and log2_r[0] == 0
    h = TWO**-LOG_BITS
    cubic = fit(lambda u: (mpmath.log1p(u) - u + u * u / 2) / u**3 if u != 0 else mpmath.mpf(1) / 3,
                h, 1)
    assert cubic[0] > 0 and cubic[1] < 0
    cubic = [nint(abs(c) * TWO**CUBIC_SCALE) for c in cubic]
    e_ln2 = [nint(e * mpmath.ln(2) * TWO**58) for e in range(-32, 31)]
    return recip, ln_r, log2_r, cubic, e_ln2


def emulate_log_fast(recip, cubic, mag):
    """(e, j, P): mag / 2^32 = 2^e m, P = ln(1 + u) 2^72 as log_parts computes it."""
    n = mag.bit_length() - 1
    m = mag << (63 - n)
    j = (m >> 55) & (LOG_SIZE - 1)
    u = ((m >> 7) * recip[j]) & M64
    assert (m >> 7) * recip[j] >> 72 == 1  # (1 + u) 2^72 with u < 2^-8
    s = mulhi(u, u)
    u39 = u >> 33
    assert u39 * cubic[1] <= M64
    inner = cubic[0] - ((u39 * cubic[1]) >> 39)
    assert 0 < inner and u39 * inner <= M64
    w = (u39 * inner) >> 33
    assert (s >> 31) * w <= M64
    return n - 32, j, u - (s >> 9) + (((s >> 31) * w) >> 17)


def check_log_fast(tables, rng):
    """Absolute errors of ln and log2 at 2^-58 before the final rounding."""
    recip, ln_r, log2_r, cubic, e_ln2 = tables
    log2e_hi = nint(TWO**127 / mpmath.ln(2)) >> 64
    worst_ln = worst_log2 = mpmath.mpf(0)
    samples = [1, 2, 3, (1 << 63) - 1, 1 << 32, (1 << 32) - 1, (1 << 32) + 1]
    for j in range(LOG_SIZE):
        base = (LOG_SIZE + j) << 47
        samples += [base, base + 1, base + (1 << 47) - 1, base + (1 << 46)]
        samples += [base + rng.getrandbits(47) for _ in range(20)]
    samples += [rng.getrandbits(63) | 1 << 62 for _ in range(3000)]
    samples += [rng.getrandbits(rng.randint(1, 63)) | 1 for _ in range(3000)]
    for mag in samples:
        e, j, p = emulate_log_fast(recip, cubic, mag)
        x = mpmath.mpf(mag) / TWO**32
        ln_sum = e_ln2[e + 32] + ln_r[j] + (p >> 14)
        log2_sum = (e << 58) + log2_r[j] + (mulhi(p, log2e_hi) >> 13)
        worst_ln = max(worst_ln, abs(mpmath.mpf(ln_sum) / TWO**58 - mpmath.ln(x)))
        worst_log2 = max(worst_log2, abs(mpmath.mpf(log2_sum) / TWO**58 - mpmath.log(x, 2)))
    return worst_ln, worst_log2


# ---- extended log2 ------------------------------------------------------------------------------

def ext_constants():
    ln2 = mpmath.ln(2)
    inv_ln2 = nint(TWO**127 / ln2)  # Q1.127
    half_inv_ln2 = nint(TWO**128 / (2 * ln2))  # Q0.128
    tail = []
    for i, k in enumerate(range(3, 7)):
        scaled = nint(TWO ** (65 - 13 * i) / (k * ln2))
        assert 0 < scaled <= M64
        tail.append(scaled)
    assert inv_ln2 < 1 << 128 and half_inv_ln2 < 1 << 128
    return inv_ln2, half_inv_ln2, tail


def mul128hi(a, b):
    return (a * b) >> 128


def emulate_log2_ext(recip1, log2_r1, recip2, log2_r2, consts, mag):
    """log2(mag / 2^32) * 2^120 as an integer (the C++ keeps it as two's complement 128-bit)."""
    inv_ln2, half_inv_ln2, tail = consts
    n = mag.bit_length() - 1
    e = n - 32
    m = mag << (63 - n)
    j1 = (m >> 56) & (TABLE_SIZE - 1)
    u79 = m * recip1[j1] - (1 << 79)
    j2 = u79 >> 65
    assert 0 <= j2 < TABLE_SIZE
    r2 = recip2[j2]
    u103 = u79 * r2 - (((1 << RECIP2_BITS) - r2) << 79)
    assert 0 <= u103 < 1 << 90
    uq = u103 << 38
    a1 = mul128hi(uq, inv_ln2) >> 20
    usq = mul128hi(uq, uq)
    a2 = mul128hi(usq, half_inv_ln2) >> 34
    u77 = uq >> 64
    acc = tail[-1]
    for c in reversed(tail[:-1]):
        v = mulhi(u77, acc)
        assert c >= v
        acc = c - v
    u2 = mulhi(u77, u77)
    u3 = mulhi(u2, u77)
    t = mulhi(u3, acc) << 16
    return (e << 120) + (log2_r1[j1] >> 8) + (log2_r2[j2] >> 8) + a1 - a2 + t


def check_log2_ext(recip1, log2_r1, recip2, log2_r2, consts, rng):
    worst = mpmath.mpf(0)
    samples = [1, 2, 3, (1 << 63) - 1, 1 << 63, 1 << 32, (1 << 32) - 1, (1 << 32) + 1]
    for j in range(TABLE_SIZE):
        base = (TABLE_SIZE + j) << 56
        for k in range(TABLE_SIZE):
            samples.append(base + (k << 42) + rng.getrandbits(42))
        samples += [base, base + (1 << 56) - 1]
    samples += [rng.getrandbits(64) | 1 << 63 for _ in range(2000)]
    samples += [(1 << 32) + rng.getrandbits(20) for _ in range(500)]
    samples += [(1 << 32) - rng.getrandbits(20) for _ in range(500)]
    for mag in samples:
        got = emulate_log2_ext(recip1, log2_r1, recip2, log2_r2, consts, mag)
        exact = mpmath.log(mpmath.mpf(mag) / TWO**32, 2) * TWO**120
        worst = max(worst, abs(got - exact))
    return worst / TWO**120


# ---- output -------------------------------------------------------------------------------------

def log2f(x):
    return float(mpmath.log(x, 2)) if x > 0 else float("-inf")


def words(v):
    return f"{{0x{v >> 64:016X}, 0x{v & M64:016X}}}"


def print_array(ctype, name, values, fmt, per_line):
    print(f"constexpr std::array<{ctype}, {len(values)}> {name}{{{{")
    for i in range(0, len(values), per_line):
        print("    " + " ".join(fmt(v) + "," for v in values[i:i + per_line]))
    print("}};")


def main():
    rng = random.Random(20240229)
    exp_table, exp_cubic, ln2_q63, index_scale = exp_tables()
    exp_fit = fit_error(lambda h: (mpmath.expm1(h) - h - h * h / 2) / h**3 if h != 0
                        else mpmath.mpf(1) / 6, EXP_H_MAX,
                        [mpmath.mpf(c) / TWO**CUBIC_SCALE for c in exp_cubic], 3)
    exp_err, exp2_err = check_exp(exp_table, exp_cubic, ln2_q63, index_scale, rng)
    margin = exp_index_margin()
    # exp's h > 0: the constant's rounding (< 2^12.1 units of 2^-71) stays below the least h.
    assert margin > TWO**-38 and margin * mpmath.ln(2) / EXP2_SIZE * TWO**71 > 2**12.1
    assert exp_err < TWO**-50 and exp2_err < TWO**-50

    recip1, recip2 = recip_tables()
    u2_sup = stage2_bound(recip2)
    assert u2_sup < TWO**-13
    log2_r1, log2_r2 = log_tables(recip1, recip2)
    fast = fast_log_tables()
    log_recip, ln_r, log2_r, log_cubic, e_ln2 = fast
    log_fit = fit_error(lambda u: (mpmath.log1p(u) - u + u * u / 2) / u**3 if u != 0
                        else mpmath.mpf(1) / 3, TWO**-LOG_BITS,
                        [mpmath.mpf(c) / TWO**CUBIC_SCALE * (-1)**i
                         for i, c in enumerate(log_cubic)], 3)
    ln_err, log2_err = check_log_fast(fast, rng)
    assert ln_err < TWO**-44 and log2_err < TWO**-44
    consts = ext_constants()
    ext_err = check_log2_ext(recip1, log2_r1, recip2, log2_r2, consts, rng)
    assert ext_err < TWO**-96

    log2e = nint(TWO**127 / mpmath.ln(2))
    hexa = lambda v: f"0x{v:016X}"
    print("// ---- Generated by scripts/gen/explog_tables.py (do not edit by hand) ----")
    print(f"// Sampled errors of the exact integer evaluation: exp mantissa "
          f"2^{log2f(exp_err):.1f}, exp2 mantissa 2^{log2f(exp2_err):.1f}")
    print(f"// relative (polynomial fit 2^{log2f(exp_fit):.1f}); ln 2^{log2f(ln_err):.1f}, "
          f"log2 2^{log2f(log2_err):.1f} absolute before the")
    print(f"// final rounding (fit 2^{log2f(log_fit):.1f}); extended log2 2^{log2f(ext_err):.1f} "
          f"absolute. Stage-2 reduction bound")
    print(f"// u2 < 2^{log2f(u2_sup):.4f}. exp's index margin |x 256/ln2 - n| > "
          f"2^{log2f(margin):.1f} for x != 0.")
    print()
    print("// 2^(j/256), Q1.63, rounded to nearest.")
    print_array("std::uint64_t", "kExp2Table", exp_table, hexa, 4)
    print("// (e^h - 1 - h - h^2/2) / h^3 ~ c3 + c4 h on [0, (ln2/256)(1 + 2^-12)]; "
          "c_i 2^34.")
    print(f"constexpr std::array<std::uint64_t, 2> kExpCubic{{{{"
          f"{', '.join(f'0x{c:08X}' for c in exp_cubic)}}}}};")
    print("// ln2 2^63, and round(2^25 / ln2): exp's n = floor(raw kExpIndexScale / 2^49 - 2^-13).")
    print(f"constexpr std::uint64_t kLn2Q63 = 0x{ln2_q63:016X};")
    print(f"constexpr std::int64_t kExpIndexScale = 0x{index_scale:07X};")
    print("// ceil(2^16 / (1 + j/256)): r = kLogRecip[j] / 2^16, u = m r - 1 in [0, 2^-8).")
    print_array("std::uint32_t", "kLogRecip", log_recip, lambda v: f"0x{v:05X}", 8)
    print("// -ln(r) and -log2(r), 2^58, rounded to nearest.")
    print_array("std::uint64_t", "kLnRecip", ln_r, hexa, 4)
    print_array("std::uint64_t", "kLog2Recip", log2_r, hexa, 4)
    print("// |(ln(1 + u) - u + u^2/2) / u^3| ~ c3 - c4 u on [0, 2^-8]: magnitudes, 2^34.")
    print(f"constexpr std::array<std::uint64_t, 2> kLogCubic{{{{"
          f"{', '.join(f'0x{c:09X}' for c in log_cubic)}}}}};")
    print("// e ln2 2^58 rounded to nearest, for e = -32..30 (log's binary exponent).")
    print_array("std::int64_t", "kExponentLn2", e_ln2,
                lambda v: f"-0x{-v:015X}" if v < 0 else f"0x{v:015X}", 3)
    print("// ceil(2^16 / (1 + j/128)): r1 = kRecip1[j] / 2^16, u1 = m r1 - 1 in [0, 2^-7).")
    print_array("std::uint32_t", "kRecip1", recip1, lambda v: f"0x{v:05X}", 8)
    print("// -log2(r1), Q0.128, rounded to nearest.")
    print_array("wide::U128", "kLog2Recip1", log2_r1, words, 2)
    print("// ceil(2^24 / (1 + j/2^14)): r2 = kRecip2[j] / 2^24.")
    print_array("std::uint32_t", "kRecip2", recip2, lambda v: f"0x{v:07X}", 6)
    print("// -log2(r2), Q0.128, rounded to nearest.")
    print_array("wide::U128", "kLog2Recip2", log2_r2, words, 2)
    inv_ln2, half_inv_ln2, tail = consts
    # One constant serves as 1/ln2 in Q1.127 (the u2 term; its high word is log2's 1/ln2 in Q1.63)
    # and as 1/(2 ln2) in Q0.128 (the u2^2 term).
    assert inv_ln2 == half_inv_ln2 == log2e
    print("// 1/(k ln2) for k = 3..6, scaled by 2^(65 - 13 (k - 3)).")
    print_array("std::uint64_t", "kLog2Tail", tail, hexa, 4)
    print("// log2(e) = 1/ln2 in Q1.127, which is also 1/(2 ln2) in Q0.128.")
    print(f"constexpr wide::U128 kLog2E{words(log2e)};")
    print("// ---- End of generated block ----")


if __name__ == "__main__":
    main()
