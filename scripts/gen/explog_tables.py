#!/usr/bin/env python3
"""Generates the tables and coefficients of fixed/src/exp_log.cpp and checks their error budgets.

Everything here mirrors the integer evaluation in exp_log.cpp bit for bit (the `emulate_*`
functions), so the sampled errors below are the errors of the C++ code, not of an idealisation.

exp2 mantissa, 2^f for f = F / 2^64 in [0, 1):
    j = F >> 56 selects 2^(j/256) from kExp2Table (Q1.63, rounded to nearest); the rest
    g = (F mod 2^56) / 2^64 is in [0, 2^-8) and G = g * 2^72 fits 64 bits exactly.
    2^g - 1 = g * Q(g), Q of degree 4 fitted at Chebyshev nodes (mpmath.chebyfit) on [0, 2^-8],
    evaluated by Estrin's scheme on unsigned values with S = mulhi(G, G) = g^2 2^80:
    Q = c0 + mulhi(G, c1) + mulhi(S, c2 + mulhi(G, c3) + mulhi(S, c4)), p = mulhi(Q, G).
    The coefficient c_i (constant first, i = 0..4) is stored scaled by 2^(64 - 8 i) so each
    product lines up with the coefficient it is added to; then M = T + round(T * p / 2^72).

log2 and ln of m in [1, 2) (fast path, 64-bit):
    j = top 7 fraction bits of m; r1 = kRecip1[j] / 2^16 = ceil(2^16 / (1 + j/128)) / 2^16, so that
    u = m r1 - 1 is exactly computable (a 64 x 17-bit product) and lies in [0, 2^-7).
    log2(m) = -log2(r1) + u * Q(u), with -log2(r1) from kLog2Recip1 (Q0.128; the fast path uses
    the high word) and Q of degree 5 fitted (chebyfit) on [0, 2^-7]; ln likewise with kLnRecip1
    (Q0.64).
    Estrin on magnitudes with alternating signs, U = u 2^71, S = mulhi(U, U) = u^2 2^78:
    Q = c0 - mulhi(U, c1) + mulhi(S, c2 - mulhi(U, c3) + mulhi(S, c4 - mulhi(U, c5))),
    c_i (constant first, i = 0..5) scaled by 2^(63 - 7 i); p = mulhi(U, Q) / 2^6.

log2 in extended precision (for pow: |error| < 2^-96 absolute):
    a second exact reduction: j2 = floor(u1 * 2^14), r2 = kRecip2[j2] / 2^24 =
    ceil(2^24 / (1 + j2 / 2^14)) / 2^24, u2 = (1 + u1) r2 - 1 in [0, 2^-14 + 2^-24), exact in 103
    fraction bits. log2(1 + u2) = u2/ln2 - u2^2/(2 ln2) + u2^3 (c3 - u2 (c4 - u2 (c5 - u2 c6)))
    (Taylor; truncation < 2^-100): the first two terms in 128-bit arithmetic, the tail in 64-bit.

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
EXP2_DEGREE = 4  # Q(g) degree: 5 coefficients
LOG_DEGREE = 5  # Q(u) degree: 6 coefficients


def mulhi(a, b):
    assert 0 <= a <= M64 and 0 <= b <= M64
    return (a * b) >> 64


def nint(x):
    return int(mpmath.nint(x))


def fit(f, h, degree):
    """Near-minimax coefficients (constant first) of f on [0, h] via Chebyshev interpolation."""
    coeffs, _ = mpmath.chebyfit(f, [0, h], degree + 1, error=True)
    return list(reversed(coeffs))


# ---- exp2 ---------------------------------------------------------------------------------------

def exp2_tables():
    table = [nint(TWO ** (mpmath.mpf(j) / EXP2_SIZE) * TWO**63) for j in range(EXP2_SIZE)]
    assert table[0] == 1 << 63 and all(t <= M64 for t in table)
    h = TWO**-EXP2_BITS
    q = fit(lambda g: (TWO**g - 1) / g if g != 0 else mpmath.ln(2), h, EXP2_DEGREE)
    poly = []
    for i, c in enumerate(q):
        assert c > 0
        scaled = nint(c * TWO ** (64 - EXP2_BITS * i))
        assert 0 < scaled <= M64
        poly.append(scaled)
    return table, poly


def emulate_exp2_mantissa(table, poly, f):
    j = f >> (64 - EXP2_BITS)
    g = (f << EXP2_BITS) & M64
    g2 = mulhi(g, g)
    inner = poly[2] + mulhi(g, poly[3]) + mulhi(g2, poly[4])
    q = poly[0] + mulhi(g, poly[1]) + mulhi(g2, inner)
    assert inner <= M64 and q <= M64
    p = mulhi(q, g)
    t = table[j]
    half = 1 << (EXP2_BITS - 1)
    corr = ((t * p >> 64) + half) >> EXP2_BITS
    m = t + corr
    return min(m, M64)


def check_exp2(table, poly, rng):
    worst = mpmath.mpf(0)
    samples = []
    low = 64 - EXP2_BITS
    for j in range(EXP2_SIZE):
        base = j << low
        samples += [base, base + 1, base + (1 << (low - 1)), base + (1 << low) - 1]
        samples += [base + rng.getrandbits(low) for _ in range(20)]
    samples += [rng.getrandbits(64) for _ in range(4000)]
    samples += [rng.getrandbits(32) << 32 for _ in range(2000)]
    for f in samples:
        m = emulate_exp2_mantissa(table, poly, f)
        exact = TWO ** (mpmath.mpf(f) / TWO**64) * TWO**63
        worst = max(worst, abs(m - exact))
    assert emulate_exp2_mantissa(table, poly, 0) == 1 << 63
    return worst  # in units of 2^-63 of the mantissa (relative error <= worst * 2^-63)


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
    ln_r1 = [nint(-mpmath.log(mpmath.mpf(r) / TWO**RECIP1_BITS) * TWO**64) for r in recip1]
    log2_r2 = [nint(-mpmath.log(mpmath.mpf(r) / TWO**RECIP2_BITS, 2) * TWO**128) for r in recip2]
    assert log2_r1[0] == 0 and ln_r1[0] == 0 and log2_r2[0] == 0
    assert all(0 <= v < 1 << 128 for v in log2_r1 + log2_r2) and all(v <= M64 for v in ln_r1)
    return log2_r1, ln_r1, log2_r2


def log_poly(scale_fn):
    h = TWO**-INDEX_BITS
    q = fit(lambda u: mpmath.log1p(u) / u * scale_fn if u != 0 else scale_fn, h, LOG_DEGREE)
    poly = []
    for i, c in enumerate(q):
        # Alternating signs: the evaluation works on magnitudes.
        assert (c > 0) == (i % 2 == 0), (i, c)
        scaled = nint(abs(c) * TWO ** (63 - 7 * i))
        assert 0 < scaled <= M64
        poly.append(scaled)
    return poly


def emulate_log_fast(recip1, table_hi, poly, mag):
    """Returns (e, S): log(mag / 2^32) ~ e * unit + S / 2^64 (unit is 1 for log2, ln2 for ln)."""
    n = mag.bit_length() - 1
    e = n - 32
    m = mag << (63 - n)
    j = (m >> 56) & (TABLE_SIZE - 1)
    prod = m * recip1[j]
    u79 = prod - (1 << 79)
    assert 0 <= u79 < 1 << 72
    u = u79 >> 8
    u2 = mulhi(u, u)
    high = poly[4] - mulhi(u, poly[5])
    middle = poly[2] - mulhi(u, poly[3]) + mulhi(u2, high)
    q = poly[0] - mulhi(u, poly[1]) + mulhi(u2, middle)
    assert high >= 0 and poly[2] >= mulhi(u, poly[3]) and poly[0] >= mulhi(u, poly[1])
    assert middle <= M64 and q <= M64
    p = mulhi(u, q) >> 6
    return e, table_hi[j] + p


def check_log_fast(recip1, table_hi, poly, ln_unit, rng):
    worst = mpmath.mpf(0)
    samples = [1, 2, 3, (1 << 63) - 1, 1 << 32, (1 << 32) - 1, (1 << 32) + 1]
    for j in range(TABLE_SIZE):
        base = (TABLE_SIZE + j) << 56
        samples += [base, base + 1, base + (1 << 56) - 1, base + (1 << 55)]
        samples += [base + rng.getrandbits(56) for _ in range(30)]
    samples += [rng.getrandbits(63) | 1 << 62 for _ in range(3000)]
    samples += [rng.getrandbits(rng.randint(1, 63)) | 1 for _ in range(2000)]
    for mag in samples:
        e, s = emulate_log_fast(recip1, table_hi, poly, mag)
        x = mpmath.mpf(mag) / TWO**32
        if ln_unit:
            got = mpmath.mpf(nint(e * mpmath.ln(2) * TWO**64) + s) / TWO**64
            exact = mpmath.ln(x)
        else:
            got = e + mpmath.mpf(s) / TWO**64
            exact = mpmath.log(x, 2)
        worst = max(worst, abs(got - exact))
    return worst


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
    exp2_table, exp2_poly = exp2_tables()
    exp2_err = check_exp2(exp2_table, exp2_poly, rng)
    assert exp2_err < 1.1

    recip1, recip2 = recip_tables()
    u2_sup = stage2_bound(recip2)
    assert u2_sup < TWO**-13
    log2_r1, ln_r1, log2_r2 = log_tables(recip1, recip2)
    log2_poly = log_poly(1 / mpmath.ln(2))
    ln_poly = log_poly(1)
    log2_hi = [v >> 64 for v in log2_r1]
    log2_err = check_log_fast(recip1, log2_hi, log2_poly, False, rng)
    ln_err = check_log_fast(recip1, ln_r1, ln_poly, True, rng)
    assert log2_err < TWO**-58 and ln_err < TWO**-58
    consts = ext_constants()
    ext_err = check_log2_ext(recip1, log2_r1, recip2, log2_r2, consts, rng)
    assert ext_err < TWO**-96

    log2e = nint(TWO**127 / mpmath.ln(2))
    # exp's argument: log2(e) 2^89 = kLog2E.hi 2^26 + kLog2ELow26 (|x| < 2^5 needs ~90 bits, and a
    # 26-bit tail times a 37-bit raw fits one 64-bit multiply).
    log2e_89 = nint(TWO**89 / mpmath.ln(2))
    log2e_low26 = log2e_89 - ((log2e >> 64) << 26)
    assert 0 <= log2e_low26 < 1 << 26
    hexa = lambda v: f"0x{v:016X}"
    print("// ---- Generated by scripts/gen/explog_tables.py (do not edit by hand) ----")
    print(f"// Sampled errors of the exact integer evaluation: exp2 mantissa "
          f"{float(exp2_err):.3f} units of 2^-63;")
    print(f"// log2 2^{log2f(log2_err):.1f}, ln 2^{log2f(ln_err):.1f} (fast path, absolute); "
          f"extended log2 2^{log2f(ext_err):.1f} absolute.")
    print(f"// Stage-2 reduction bound u2 < 2^{log2f(u2_sup):.4f}.")
    print()
    print("// 2^(j/256), Q1.63, rounded to nearest.")
    print_array("std::uint64_t", "kExp2Table", exp2_table, hexa, 4)
    print(f"// (2^g - 1) / g on [0, 2^-8], degree {EXP2_DEGREE}; c_i scaled by 2^(64 - 8 i), "
          "constant first.")
    print_array("std::uint64_t", "kExp2Poly", exp2_poly, hexa, 3)
    print("// ceil(2^16 / (1 + j/128)): r1 = kRecip1[j] / 2^16, u1 = m r1 - 1 in [0, 2^-7).")
    print_array("std::uint32_t", "kRecip1", recip1, lambda v: f"0x{v:05X}", 8)
    print("// -log2(r1), Q0.128, rounded to nearest.")
    print_array("wide::U128", "kLog2Recip1", log2_r1, words, 2)
    print("// -ln(r1), Q0.64, rounded to nearest.")
    print_array("std::uint64_t", "kLnRecip1", ln_r1, hexa, 4)
    print(f"// |log2(1 + u) / u| and |ln(1 + u) / u| on [0, 2^-7], degree {LOG_DEGREE}, signs "
          "alternating")
    print("// (+ - + ...); c_i scaled by 2^(63 - 7 i), constant first.")
    print_array("std::uint64_t", "kLog2Poly", log2_poly, hexa, 3)
    print_array("std::uint64_t", "kLnPoly", ln_poly, hexa, 3)
    print("// ceil(2^24 / (1 + j/2^14)): r2 = kRecip2[j] / 2^24.")
    print_array("std::uint32_t", "kRecip2", recip2, lambda v: f"0x{v:07X}", 6)
    print("// -log2(r2), Q0.128, rounded to nearest.")
    print_array("wide::U128", "kLog2Recip2", log2_r2, words, 2)
    inv_ln2, half_inv_ln2, tail = consts
    # One constant serves as 1/ln2 in Q1.127 (exp's argument, the u2 term) and as 1/(2 ln2) in
    # Q0.128 (the u2^2 term).
    assert inv_ln2 == half_inv_ln2 == log2e
    print("// 1/(k ln2) for k = 3..6, scaled by 2^(65 - 13 (k - 3)).")
    print_array("std::uint64_t", "kLog2Tail", tail, hexa, 4)
    print("// log2(e) = 1/ln2 in Q1.127, which is also 1/(2 ln2) in Q0.128.")
    print(f"constexpr wide::U128 kLog2E{words(log2e)};")
    e_ln2 = [nint(e * mpmath.ln(2) * TWO**64) % (1 << 128) for e in range(-32, 31)]
    print("// e ln2 2^64 rounded to nearest, two's complement, for e = -32..30 (log's binary exponent).")
    print_array("wide::U128", "kExponentLn2", e_ln2, words, 2)
    print("// round(log2(e) 2^89) - kLog2E.hi 2^26: the 26 bits of log2(e) after kLog2E.hi, rounded.")
    print(f"constexpr std::uint64_t kLog2ELow26 = 0x{log2e_low26:07X};")
    print("// ---- End of generated block ----")


if __name__ == "__main__":
    main()
