// The measured functions: calls, MPFR references, documented domain values, random inputs and
// edge inputs. The documented values are those of fixed/include/detsim/fixed/math.hpp.
#include <cmath>

#include <detsim/fixed/math.hpp>
#include "catalog.hpp"

namespace detsim::accuracy::detail {
namespace {

constexpr std::int64_t one = raw_one;

// ---- Shared input pieces -----------------------------------------------------------------------

void add_values(ArgsList& list, const std::vector<std::int64_t>& values) {
  for (const std::int64_t v : values)
    list.push_back({raw(v)});
}

void add_pairs(ArgsList& list, const std::vector<std::int64_t>& first,
               const std::vector<std::int64_t>& second) {
  for (const std::int64_t a : first) {
    for (const std::int64_t b : second)
      list.push_back({raw(a), raw(b)});
  }
}

void unary_specials(ArgsList& list) {
  add_values(list, special_values());
}

void pair_specials(ArgsList& list) {
  const auto values = special_values_small();
  add_pairs(list, values, values);
}

/// Nearest raw of f(c) for an MPFR function f and an unsigned constant c.
std::int64_t nearest_of(int (*f)(mpfr_ptr, mpfr_srcptr, mpfr_rnd_t), mpfr_srcptr argument) {
  Mp value;
  f(value.get(), argument, MPFR_RNDN);
  return nearest_raw(value.get());
}

/// ln or log2 of 2^e.
std::int64_t log_of_power(int (*f)(mpfr_ptr, mpfr_srcptr, mpfr_rnd_t), long e) {
  Mp argument;
  mpfr_set_si_2exp(argument.get(), 1, e, MPFR_RNDN);
  return nearest_of(f, argument.get());
}

/// Samples for a raw value from a double (tools only: shapes pow's inputs, never a reference).
std::int64_t raw_from_double(double v) {
  const double scaled = std::ldexp(v, Fixed::fraction_bits);
  if (!(scaled < 9.2e18)) return raw_max;
  if (!(scaled > -9.2e18)) return raw_min;
  return std::llround(scaled);
}

bool is_integer(Fixed x) {
  return (x.raw() & 0xFFFFFFFF) == 0;
}

// ---- Roots -------------------------------------------------------------------------------------

void sqrt_edges(ArgsList& list) {
  unary_specials(list);
  // Perfect squares raw = j^2 (x = (j 2^-16)^2: sqrt exactly on the grid) and their neighbours.
  Rng rng(0x5351'5254U);
  std::vector<std::int64_t> roots;
  for (std::int64_t j = 1; j <= 2000; ++j)
    roots.push_back(j);
  for (int b = 11; b < 32; ++b)
    roots.push_back(std::int64_t{1} << b);
  roots.push_back(3037000499);  // floor(sqrt(2^63 - 1))
  for (int i = 0; i < 2000; ++i)
    roots.push_back(1 + static_cast<std::int64_t>(rng.below(3037000499)));
  for (const std::int64_t j : roots)
    add_around(list, j * j, 1);
}

void rsqrt_edges(ArgsList& list) {
  unary_specials(list);
  for (int b = 0; b < 63; b += 2)
    add_around(list, std::int64_t{1} << b, 2);  // x = 4^k
}

void hypot_edges(ArgsList& list) {
  pair_specials(list);
  // Pythagorean triples scaled through every binade: exact results.
  const std::int64_t triples[][2] = {{3, 4}, {5, 12}, {8, 15}, {20, 21}, {65, 72}};
  for (const auto& t : triples) {
    for (int b = 0; b < 55; ++b) {
      const std::int64_t x = t[0] << b;
      const std::int64_t y = t[1] << b;
      if (y > raw_max / 2) break;
      list.push_back({raw(x), raw(y)});
      list.push_back({raw(-y), raw(x + 1)});
    }
  }
  // Around the saturation threshold: x = y = 2^31 / sqrt(2), and one axis near 2^31.
  Mp threshold;
  mpfr_sqrt_ui(threshold.get(), 2, MPFR_RNDN);
  mpfr_ui_div(threshold.get(), 1, threshold.get(), MPFR_RNDN);
  mpfr_mul_2ui(threshold.get(), threshold.get(), 31, MPFR_RNDN);
  const std::int64_t diagonal = nearest_raw(threshold.get());
  for (std::int64_t d = -4; d <= 4; ++d) {
    for (std::int64_t e = -4; e <= 4; ++e)
      list.push_back({raw(diagonal + d), raw(diagonal + e)});
  }
  // Extreme ratios: one side at every power of two against the extremes and 1.
  for (int b = 0; b < 63; ++b) {
    const std::int64_t p = std::int64_t{1} << b;
    for (const std::int64_t big : {raw_max, raw_max - 1, raw_min, raw_min + 1, one}) {
      list.push_back({raw(big), raw(p)});
      list.push_back({raw(-p), raw(big)});
    }
  }
}

// ---- Trigonometry ------------------------------------------------------------------------------

void angle_edges(ArgsList& list, bool poles) {
  unary_specials(list);
  const auto multiples = half_pi_multiples();
  for (std::size_t i = 0; i < multiples.size(); ++i) {
    const auto& m = multiples[i];
    for (std::int64_t d = -2; d <= 2; ++d) {
      std::int64_t r = 0;
      if (offset(m.raw, d, &r)) add_both_signs(list, r);
    }
    // tan's poles are the odd multiples: sweep the distance from the pole over every scale, which
    // sweeps |tan| from 2^-8 to beyond the Fixed range.
    const bool sampled = i < 64 || i + 64 >= multiples.size() || i % 8 == 0;
    if (poles && (m.k & 1U) != 0 && sampled) {
      ArgsList sweep;
      add_sweep(sweep, m.raw, 40);
      for (const Args& a : sweep)
        add_both_signs(list, a[0].raw());
    }
  }
  // pi/4 and pi/6 multiples (tan = 1, sin = 1/2) with neighbours.
  Mp angle;
  for (const unsigned divisor : {4U, 6U, 3U}) {
    mpfr_const_pi(angle.get(), MPFR_RNDN);
    mpfr_div_ui(angle.get(), angle.get(), divisor, MPFR_RNDN);
    const std::int64_t r = nearest_raw(angle.get());
    for (std::int64_t d = -2; d <= 2; ++d)
      add_both_signs(list, r + d);
  }
}

void sin_edges(ArgsList& list) {
  angle_edges(list, false);
}
void tan_edges(ArgsList& list) {
  angle_edges(list, true);
}

void unit_interval_edges(ArgsList& list) {
  unary_specials(list);
  // 1 - 2^-j and its neighbours: where asin and acos are steepest.
  for (int j = 0; j <= 32; ++j) {
    const std::int64_t r = one - (one >> j);
    for (std::int64_t d = -1; d <= 1; ++d)
      add_both_signs(list, r + d);
  }
  // sqrt(1/2) and sqrt(3)/2 with neighbours.
  Mp v;
  for (const unsigned n : {2U, 3U}) {
    mpfr_sqrt_ui(v.get(), n, MPFR_RNDN);
    mpfr_div_2ui(v.get(), v.get(), 1, MPFR_RNDN);
    const std::int64_t r = nearest_raw(v.get());
    for (std::int64_t d = -2; d <= 2; ++d)
      add_both_signs(list, r + d);
  }
}

void atan_edges(ArgsList& list) {
  unary_specials(list);
  add_sweep(list, one, 32);
  add_sweep(list, -one, 32);
}

void atan2_edges(ArgsList& list) {
  pair_specials(list);
  // Extreme ratios, and points just off the negative x axis (results near +-pi).
  for (int b = 0; b < 63; ++b) {
    const std::int64_t p = std::int64_t{1} << b;
    for (const std::int64_t big : {raw_max, raw_min, one, -one}) {
      for (const std::int64_t s : {p, -p}) {
        list.push_back({raw(s), raw(big)});
        list.push_back({raw(big), raw(s)});
      }
    }
  }
  // The diagonals, where the result is a multiple of pi/4.
  for (const std::int64_t v : special_values_small()) {
    if (v == raw_min) continue;
    list.push_back({raw(v), raw(v)});
    list.push_back({raw(v), raw(-v)});
    list.push_back({raw(v), raw(v + (v < raw_max ? 1 : -1))});
  }
}

// ---- Exponentials and logarithms ---------------------------------------------------------------

void threshold_edges(ArgsList& list, std::int64_t threshold) {
  add_around(list, threshold, 16);
  add_sweep(list, threshold, 40);
}

void exp_edges(ArgsList& list) {
  unary_specials(list);
  // Saturation at ln(max), the underflow rounding boundary at ln(2^-33), the last ulp at
  // ln(2^-32), and the change of rule at ln(2^16).
  Mp max_value;
  set_fixed(max_value.get(), Fixed::max());
  threshold_edges(list, nearest_of(mpfr_log, max_value.get()));
  for (const long e : {-33L, -32L, 16L})
    threshold_edges(list, log_of_power(mpfr_log, e));
  for (std::int64_t k = -40; k <= 40; ++k)
    add_around(list, k * one, 1);
}

void exp2_edges(ArgsList& list) {
  unary_specials(list);
  Mp max_value;
  set_fixed(max_value.get(), Fixed::max());
  threshold_edges(list, nearest_of(mpfr_log2, max_value.get()));
  for (const std::int64_t k : {-33, -32, 16, 31})
    threshold_edges(list, k * one);
  for (std::int64_t k = -80; k <= 80; ++k)
    add_around(list, k * (one / 2), 1);
}

void log_edges(ArgsList& list) {
  unary_specials(list);
  add_sweep(list, one, 32);  // log(1 + d): tiny results
  Mp v;
  for (long k = -22; k <= 21; ++k) {  // e^k
    mpfr_set_si(v.get(), k, MPFR_RNDN);
    mpfr_exp(v.get(), v.get(), MPFR_RNDN);
    add_around(list, nearest_raw(v.get()), 1);
  }
  for (int b = 0; b < 63; ++b)
    add_around(list, std::int64_t{1} << b, 2);
}

void pow_edges(ArgsList& list) {
  pair_specials(list);
  const std::int64_t two = 2 * one;
  for (std::int64_t k = -40; k <= 40; ++k) {  // 2^k exactly and with y one ulp off
    for (std::int64_t d = -1; d <= 1; ++d)
      list.push_back({raw(two), raw(k * one + d)});
    list.push_back({raw(-two), raw(k * one)});  // negative base, integer exponent
  }
  // Saturation and underflow thresholds of 2^y and e^y.
  for (const std::int64_t k : {31, -33, -32}) {
    ArgsList ys;
    threshold_edges(ys, k * one);
    for (const Args& y : ys)
      list.push_back({raw(two), y[0]});
  }
  Mp e_value;
  mpfr_set_ui(e_value.get(), 1, MPFR_RNDN);
  mpfr_exp(e_value.get(), e_value.get(), MPFR_RNDN);
  const std::int64_t e_raw = nearest_raw(e_value.get());
  Mp max_value;
  set_fixed(max_value.get(), Fixed::max());
  {
    ArgsList ys;
    threshold_edges(ys, nearest_of(mpfr_log, max_value.get()));
    for (const Args& y : ys)
      list.push_back({raw(e_raw), y[0]});
  }
  // x near 1 with large y: 1 +- 2^-j against y = +-2^k.
  for (int j = 0; j < 32; ++j) {
    for (const std::int64_t x : {one + (std::int64_t{1} << j), one - (std::int64_t{1} << j)}) {
      for (int k = 0; k <= 31; k += 3) {
        const std::int64_t y = one << k;
        if (k == 31) {
          list.push_back({raw(x), raw(raw_max)});
          list.push_back({raw(x), raw(raw_min)});
        } else {
          list.push_back({raw(x), raw(y)});
          list.push_back({raw(x), raw(-y)});
        }
      }
    }
  }
  // Square roots, reciprocals, squares, and odd and even powers of -1.
  for (const std::int64_t x : special_values_small()) {
    for (const std::int64_t y : {one / 2, -one, 2 * one, -one / 2})
      list.push_back({raw(x), raw(y)});
  }
  for (std::int64_t k = -5; k <= 5; ++k)
    list.push_back({raw(-one), raw(k * one)});
}

// ---- Core operations ---------------------------------------------------------------------------

void mul_edges(ArgsList& list) {
  pair_specials(list);
  // Exact ties: odd * (2j + 1) / 2 lands halfway between two values.
  Rng rng(0x4D55'4C54'4945U);
  for (int i = 0; i < 4000; ++i) {
    const std::int64_t a = with_sign(rng.coin(), rng.log_magnitude(0, 40) | 1U);
    const std::int64_t half_odd = static_cast<std::int64_t>(2 * rng.below(1000) + 1) << 31;
    list.push_back({raw(a), raw(rng.coin() ? half_odd : -half_odd)});
  }
  // Products at the saturation threshold: 2^k * 2^(31 - k) == 2^31 is just beyond max(), and one
  // ulp less is not.
  for (int k = 1; k <= 30; ++k) {
    const std::int64_t a = one << k;
    const std::int64_t b = std::int64_t{1} << (63 - k);
    for (std::int64_t d = -1; d <= 0; ++d) {
      list.push_back({raw(a), raw(b + d)});
      list.push_back({raw(-a), raw(b + d)});
    }
  }
}

void div_edges(ArgsList& list) {
  pair_specials(list);
  // Exact ties: a / 2^s with a's low s bits equal to 2^(s-1).
  Rng rng(0x4449'5654'4945U);
  for (int i = 0; i < 4000; ++i) {
    const int s = 1 + static_cast<int>(rng.below(30));
    const std::uint64_t mask = (std::uint64_t{1} << s) - 1;
    const std::uint64_t magnitude =
        (rng.log_magnitude(s, 62) & ~mask) | (std::uint64_t{1} << (s - 1));
    const std::int64_t a = with_sign(rng.coin(), magnitude);
    const std::int64_t b = one << s;
    list.push_back({raw(a), raw(rng.coin() ? b : -b)});
  }
}

void lerp_edges(ArgsList& list) {
  const std::vector<std::int64_t> ends = {
      0, 1, -1, one, -one, one << 30, -(one << 30), raw_max, raw_max - 1, raw_min, raw_min + 1};
  const std::vector<std::int64_t> ts = {0,       1,    -1,      one / 2, one - 1, one,
                                        one + 1, -one, 2 * one, raw_max, raw_min, one / 4};
  for (const std::int64_t a : ends) {
    for (const std::int64_t b : ends) {
      for (const std::int64_t t : ts)
        list.push_back({raw(a), raw(b), raw(t)});
    }
  }
  // Exact ties: b - a odd and t = 1/2 or 3/2.
  Rng rng(0x4C45'5250'5449U);
  for (int i = 0; i < 4000; ++i) {
    const std::int64_t a = rng.log_signed(0, 61);
    const std::int64_t d = with_sign(rng.coin(), rng.log_magnitude(0, 40) | 1U);
    std::int64_t b = 0;
    if (!offset(a, d, &b)) continue;
    list.push_back({raw(a), raw(b), raw(rng.coin() ? one / 2 : 3 * (one / 2))});
  }
}

// ---- Random inputs -----------------------------------------------------------------------------

Fixed uniform_full(Rng& rng) {
  return raw(rng.uniform(raw_min, raw_max));
}

void sample_full(Rng& rng, bool log_half, Args& a) {
  a[0] = log_half ? raw(rng.log_signed(0, 62)) : uniform_full(rng);
}

void sample_positive(Rng& rng, bool log_half, Args& a) {
  a[0] =
      raw(log_half ? static_cast<std::int64_t>(rng.log_magnitude(0, 62)) : rng.uniform(1, raw_max));
}

void sample_nonnegative(Rng& rng, bool log_half, Args& a) {
  a[0] =
      raw(log_half ? static_cast<std::int64_t>(rng.log_magnitude(0, 62)) : rng.uniform(0, raw_max));
}

void sample_pair_full(Rng& rng, bool log_half, Args& a) {
  for (int i = 0; i < 2; ++i) {
    a[static_cast<std::size_t>(i)] = log_half ? raw(rng.log_signed(0, 62)) : uniform_full(rng);
  }
}

void sample_unit(Rng& rng, bool log_half, Args& a) {
  if (!log_half) {
    a[0] = raw(rng.uniform(-one, one));
  } else if (rng.coin()) {
    a[0] = raw(rng.log_signed(0, 31));  // magnitude log-uniform in [2^-32, 1)
  } else {
    a[0] = raw(with_sign(rng.coin(), static_cast<std::uint64_t>(one) - rng.log_magnitude(0, 31)));
  }
}

void sample_exp(Rng& rng, bool log_half, Args& a) {
  a[0] = raw(log_half ? rng.log_signed(0, 37) : rng.uniform(-24 * one, 22 * one));
}

void sample_exp2(Rng& rng, bool log_half, Args& a) {
  a[0] = raw(log_half ? rng.log_signed(0, 38) : rng.uniform(-34 * one, 32 * one));
}

void sample_pow(Rng& rng, bool log_half, Args& a) {
  if (!log_half) {
    const std::uint64_t kind = rng.below(8);
    if (kind < 6) {  // x in (0, 16], y in [-16, 16]
      a[0] = raw(rng.uniform(1, 16 * one));
      a[1] = raw(rng.uniform(-16 * one, 16 * one));
    } else {  // x in [-16, 0): y an integer, or not (the documented 0)
      a[0] = raw(rng.uniform(-16 * one, -1));
      a[1] = kind == 6 ? Fixed::from_int(static_cast<std::int32_t>(rng.uniform(-40, 40)))
                       : raw(rng.uniform(-16 * one, 16 * one));
    }
    return;
  }
  if (rng.coin()) {
    // x log-uniform; y chosen so that log2 of the result is uniform in [-35, 33]: covers every
    // result scale, underflow and saturation included.
    a[0] = raw(static_cast<std::int64_t>(rng.log_magnitude(0, 62)));
    const double log2_x = std::log2(a[0].to_double());
    const double target = -35.0 + 68.0 * std::ldexp(static_cast<double>(rng.next() >> 11), -53);
    a[1] = log2_x == 0.0 ? raw(rng.log_signed(0, 62)) : raw(raw_from_double(target / log2_x));
  } else {
    // x near 1 with large y: 1 +- d, d log-uniform in [2^-32, 1), |y| in [1, 2^31).
    const auto d = static_cast<std::int64_t>(rng.log_magnitude(0, 31));
    a[0] = raw(rng.coin() ? one + d : one - d);
    a[1] = raw(rng.log_signed(32, 62));
  }
}

void sample_mul(Rng& rng, bool log_half, Args& a) {
  if (log_half) {
    sample_pair_full(rng, true, a);
    return;
  }
  // a uniform; b uniform where |a b| stays within 9/8 of the range, so about one in nine
  // products saturates and the rest cover the whole range.
  a[0] = uniform_full(rng);
  const double magnitude = std::fabs(a[0].to_double());
  const double bound = magnitude < 1.0 ? 9.2e18 : std::ldexp(1.125 * 2147483648.0 / magnitude, 32);
  const std::int64_t b = bound >= 9.2e18 ? raw_max : static_cast<std::int64_t>(bound);
  a[1] = raw(rng.uniform(-b, b));
}

void sample_lerp(Rng& rng, bool log_half, Args& a) {
  if (!log_half) {
    a[0] = uniform_full(rng);
    a[1] = uniform_full(rng);
    a[2] = raw(rng.uniform(0, one));
    return;
  }
  a[0] = raw(rng.log_signed(0, 62));
  a[1] = raw(rng.log_signed(0, 62));
  // t in (0, 1) log-uniform, or |t| up to 2^8 with either sign (extrapolation).
  a[2] = rng.coin() ? raw(static_cast<std::int64_t>(rng.log_magnitude(0, 31)))
                    : raw(rng.log_signed(0, 40));
}

// ---- Documented values outside the domain ------------------------------------------------------

bool sqrt_documented(const Args& a, Fixed* value, const char** rule) {
  if (a[0].raw() >= 0) return false;
  *value = Fixed::zero();
  *rule = "sqrt(x < 0) == 0";
  return true;
}

bool rsqrt_documented(const Args& a, Fixed* value, const char** rule) {
  if (a[0].raw() > 0) return false;
  *value = Fixed::max();
  *rule = "rsqrt(x <= 0) == max()";
  return true;
}

bool asin_documented(const Args& a, Fixed* value, const char** rule) {
  if (abs(a[0]) <= Fixed::one()) return false;
  *value = detsim::asin(a[0].raw() < 0 ? -Fixed::one() : Fixed::one());
  *rule = "asin(x) == asin(clamp(x, -1, 1))";
  return true;
}

bool acos_documented(const Args& a, Fixed* value, const char** rule) {
  if (abs(a[0]) <= Fixed::one()) return false;
  *value = detsim::acos(a[0].raw() < 0 ? -Fixed::one() : Fixed::one());
  *rule = "acos(x) == acos(clamp(x, -1, 1))";
  return true;
}

bool atan2_documented(const Args& a, Fixed* value, const char** rule) {
  if (a[0].raw() != 0 || a[1].raw() != 0) return false;
  *value = Fixed::zero();
  *rule = "atan2(0, 0) == 0";
  return true;
}

bool log_documented(const Args& a, Fixed* value, const char** rule) {
  if (a[0].raw() > 0) return false;
  *value = Fixed::min();
  *rule = "log(x <= 0) == min()";
  return true;
}

bool pow_documented(const Args& a, Fixed* value, const char** rule) {
  const Fixed x = a[0];
  const Fixed y = a[1];
  if (x.raw() == 0) {
    *value = y.raw() > 0 ? Fixed::zero() : (y.raw() == 0 ? Fixed::one() : Fixed::max());
    *rule = "pow(0, y) == 0, 1, max() for y > 0, y == 0, y < 0";
    return true;
  }
  if (x.raw() < 0 && !is_integer(y)) {
    *value = Fixed::zero();
    *rule = "pow(x < 0, non-integer y) == 0";
    return true;
  }
  return false;
}

bool div_documented(const Args& a, Fixed* value, const char** rule) {
  if (a[1].raw() != 0) return false;
  *value = a[0].raw() > 0 ? Fixed::max() : (a[0].raw() < 0 ? Fixed::min() : Fixed::zero());
  *rule = "x / 0 == max(), min(), 0 for x > 0, x < 0, x == 0";
  return true;
}

// ---- The table ---------------------------------------------------------------------------------

using C = Contract;

const Entry table[] = {
    {.spec = {"sqrt",
              "sqrt(x)",
              1,
              {"x"},
              C::correctly_rounded,
              "x uniform in [0, max]; x log-uniform in [2^-32, 2^31)"},
     .compute = [](const Args& a, Fixed* r) { r[0] = detsim::sqrt(a[0]); },
     .reference = [](const mpfr_ptr* in, mpfr_ptr* out,
                     Scratch&) { mpfr_sqrt(out[0], in[0], MPFR_RNDN); },
     .documented = sqrt_documented,
     .sample = sample_nonnegative,
     .edges = sqrt_edges},
    {.spec = {"rsqrt",
              "rsqrt(x)",
              1,
              {"x"},
              C::faithful,
              "x uniform in (0, max]; x log-uniform in [2^-32, 2^31)"},
     .compute = [](const Args& a, Fixed* r) { r[0] = detsim::rsqrt(a[0]); },
     .reference = [](const mpfr_ptr* in, mpfr_ptr* out,
                     Scratch&) { mpfr_rec_sqrt(out[0], in[0], MPFR_RNDN); },
     .documented = rsqrt_documented,
     .sample = sample_positive,
     .edges = rsqrt_edges},
    {.spec = {"hypot",
              "hypot(x, y)",
              2,
              {"x", "y"},
              C::correctly_rounded,
              "x, y uniform over the range; x, y log-uniform with random signs"},
     .compute = [](const Args& a, Fixed* r) { r[0] = detsim::hypot(a[0], a[1]); },
     .reference = [](const mpfr_ptr* in, mpfr_ptr* out,
                     Scratch&) { mpfr_hypot(out[0], in[0], in[1], MPFR_RNDN); },
     .sample = sample_pair_full,
     .edges = hypot_edges},
    {.spec = {"sin",
              "sin(x)",
              1,
              {"x"},
              C::faithful,
              "x uniform over the range; x log-uniform with a random sign"},
     .compute = [](const Args& a, Fixed* r) { r[0] = detsim::sin(a[0]); },
     .reference = [](const mpfr_ptr* in, mpfr_ptr* out,
                     Scratch&) { mpfr_sin(out[0], in[0], MPFR_RNDN); },
     .sample = sample_full,
     .edges = sin_edges},
    {.spec = {"cos",
              "cos(x)",
              1,
              {"x"},
              C::faithful,
              "x uniform over the range; x log-uniform with a random sign"},
     .compute = [](const Args& a, Fixed* r) { r[0] = detsim::cos(a[0]); },
     .reference = [](const mpfr_ptr* in, mpfr_ptr* out,
                     Scratch&) { mpfr_cos(out[0], in[0], MPFR_RNDN); },
     .sample = sample_full,
     .edges = sin_edges},
    {.spec = {"sincos",
              "sincos(x)",
              1,
              {"x"},
              C::faithful,
              "x uniform over the range; x log-uniform with a random sign"},
     .results = 2,
     .result_names = {"sin", "cos"},
     .compute =
         [](const Args& a, Fixed* r) {
           const SinCos sc = detsim::sincos(a[0]);
           r[0] = sc.sin;
           r[1] = sc.cos;
         },
     .reference = [](const mpfr_ptr* in, mpfr_ptr* out,
                     Scratch&) { mpfr_sin_cos(out[0], out[1], in[0], MPFR_RNDN); },
     .sample = sample_full,
     .edges = sin_edges},
    {.spec = {"tan",
              "tan(x)",
              1,
              {"x"},
              C::faithful,
              "x uniform over the range; x log-uniform with a random sign"},
     .compute = [](const Args& a, Fixed* r) { r[0] = detsim::tan(a[0]); },
     .reference = [](const mpfr_ptr* in, mpfr_ptr* out,
                     Scratch&) { mpfr_tan(out[0], in[0], MPFR_RNDN); },
     .sample = sample_full,
     .edges = tan_edges},
    {.spec = {"asin",
              "asin(x)",
              1,
              {"x"},
              C::faithful,
              "x uniform in [-1, 1]; |x| or 1 - |x| log-uniform, random sign"},
     .compute = [](const Args& a, Fixed* r) { r[0] = detsim::asin(a[0]); },
     .reference = [](const mpfr_ptr* in, mpfr_ptr* out,
                     Scratch&) { mpfr_asin(out[0], in[0], MPFR_RNDN); },
     .documented = asin_documented,
     .sample = sample_unit,
     .edges = unit_interval_edges},
    {.spec = {"acos",
              "acos(x)",
              1,
              {"x"},
              C::faithful,
              "x uniform in [-1, 1]; |x| or 1 - |x| log-uniform, random sign"},
     .compute = [](const Args& a, Fixed* r) { r[0] = detsim::acos(a[0]); },
     .reference = [](const mpfr_ptr* in, mpfr_ptr* out,
                     Scratch&) { mpfr_acos(out[0], in[0], MPFR_RNDN); },
     .documented = acos_documented,
     .sample = sample_unit,
     .edges = unit_interval_edges},
    {.spec = {"atan",
              "atan(x)",
              1,
              {"x"},
              C::faithful,
              "x uniform over the range; x log-uniform with a random sign"},
     .compute = [](const Args& a, Fixed* r) { r[0] = detsim::atan(a[0]); },
     .reference = [](const mpfr_ptr* in, mpfr_ptr* out,
                     Scratch&) { mpfr_atan(out[0], in[0], MPFR_RNDN); },
     .sample = sample_full,
     .edges = atan_edges},
    {.spec = {"atan2",
              "atan2(y, x)",
              2,
              {"y", "x"},
              C::faithful,
              "y, x uniform over the range; y, x log-uniform with random signs"},
     .compute = [](const Args& a, Fixed* r) { r[0] = detsim::atan2(a[0], a[1]); },
     .reference = [](const mpfr_ptr* in, mpfr_ptr* out,
                     Scratch&) { mpfr_atan2(out[0], in[0], in[1], MPFR_RNDN); },
     .documented = atan2_documented,
     .sample = sample_pair_full,
     .edges = atan2_edges},
    {.spec = {"exp",
              "exp(x)",
              1,
              {"x"},
              C::faithful,
              "x uniform in [-24, 22]; |x| log-uniform in [2^-32, 64), random sign"},
     .compute = [](const Args& a, Fixed* r) { r[0] = detsim::exp(a[0]); },
     .reference = [](const mpfr_ptr* in, mpfr_ptr* out,
                     Scratch&) { mpfr_exp(out[0], in[0], MPFR_RNDN); },
     .sample = sample_exp,
     .edges = exp_edges},
    {.spec = {"exp2",
              "exp2(x)",
              1,
              {"x"},
              C::faithful,
              "x uniform in [-34, 32]; |x| log-uniform in [2^-32, 128), random sign"},
     .compute = [](const Args& a, Fixed* r) { r[0] = detsim::exp2(a[0]); },
     .reference = [](const mpfr_ptr* in, mpfr_ptr* out,
                     Scratch&) { mpfr_exp2(out[0], in[0], MPFR_RNDN); },
     .sample = sample_exp2,
     .edges = exp2_edges},
    {.spec = {"log",
              "log(x)",
              1,
              {"x"},
              C::faithful,
              "x uniform in (0, max]; x log-uniform in [2^-32, 2^31)"},
     .compute = [](const Args& a, Fixed* r) { r[0] = detsim::log(a[0]); },
     .reference = [](const mpfr_ptr* in, mpfr_ptr* out,
                     Scratch&) { mpfr_log(out[0], in[0], MPFR_RNDN); },
     .documented = log_documented,
     .sample = sample_positive,
     .edges = log_edges},
    {.spec = {"log2",
              "log2(x)",
              1,
              {"x"},
              C::faithful,
              "x uniform in (0, max]; x log-uniform in [2^-32, 2^31)"},
     .compute = [](const Args& a, Fixed* r) { r[0] = detsim::log2(a[0]); },
     .reference = [](const mpfr_ptr* in, mpfr_ptr* out,
                     Scratch&) { mpfr_log2(out[0], in[0], MPFR_RNDN); },
     .documented = log_documented,
     .sample = sample_positive,
     .edges = log_edges},
    {.spec = {"pow",
              "pow(x, y)",
              2,
              {"x", "y"},
              C::faithful,
              "x in (0, 16] and y in [-16, 16] uniform, or x < 0; x log-uniform with y aimed at "
              "results 2^-35 .. 2^33, or x near 1 with |y| up to 2^31"},
     .compute = [](const Args& a, Fixed* r) { r[0] = detsim::pow(a[0], a[1]); },
     .reference = [](const mpfr_ptr* in, mpfr_ptr* out,
                     Scratch&) { mpfr_pow(out[0], in[0], in[1], MPFR_RNDN); },
     .documented = pow_documented,
     .sample = sample_pow,
     .edges = pow_edges},
    {.spec = {"mul",
              "a * b",
              2,
              {"a", "b"},
              C::correctly_rounded,
              "a uniform, b uniform with |a b| < 9/8 of the range; a, b log-uniform, random signs"},
     .compute = [](const Args& a, Fixed* r) { r[0] = a[0] * a[1]; },
     .reference = [](const mpfr_ptr* in, mpfr_ptr* out,
                     Scratch&) { mpfr_mul(out[0], in[0], in[1], MPFR_RNDN); },
     .sample = sample_mul,
     .edges = mul_edges},
    {.spec = {"div",
              "a / b",
              2,
              {"a", "b"},
              C::correctly_rounded,
              "a, b uniform over the range; a, b log-uniform with random signs"},
     .compute = [](const Args& a, Fixed* r) { r[0] = a[0] / a[1]; },
     .reference = [](const mpfr_ptr* in, mpfr_ptr* out,
                     Scratch&) { mpfr_div(out[0], in[0], in[1], MPFR_RNDN); },
     .documented = div_documented,
     .sample = sample_pair_full,
     .edges = div_edges},
    {.spec = {"lerp",
              "lerp(a, b, t)",
              3,
              {"a", "b", "t"},
              C::correctly_rounded,
              "a, b uniform, t uniform in [0, 1]; a, b log-uniform, t log-uniform in (0, 1) or "
              "|t| < 2^8"},
     .compute = [](const Args& a, Fixed* r) { r[0] = detsim::lerp(a[0], a[1], a[2]); },
     .reference =
         [](const mpfr_ptr* in, mpfr_ptr* out, Scratch& s) {
           // b - a needs 65 bits and (b - a) t + a at most 130: both exact here.
           mpfr_sub(s.a.get(), in[1], in[0], MPFR_RNDN);
           mpfr_fma(out[0], s.a.get(), in[2], in[0], MPFR_RNDN);
         },
     .sample = sample_lerp,
     .edges = lerp_edges},
};

}  // namespace

std::span<const Entry> entries() noexcept {
  return table;
}

}  // namespace detsim::accuracy::detail
