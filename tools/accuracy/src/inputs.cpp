#include "inputs.hpp"

#include <algorithm>
#include <detsim/fixed/wide.hpp>

namespace detsim::accuracy::detail {

std::uint64_t Rng::below(std::uint64_t n) noexcept {
  return wide::Default::mul(next(), n).hi;
}

std::int64_t Rng::uniform(std::int64_t lo, std::int64_t hi) noexcept {
  const std::uint64_t span = static_cast<std::uint64_t>(hi) - static_cast<std::uint64_t>(lo);
  const std::uint64_t step = span == ~std::uint64_t{0} ? next() : below(span + 1);
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(lo) + step);
}

std::uint64_t Rng::log_magnitude(int low_bit, int high_bit) noexcept {
  const auto bit = static_cast<unsigned>(
      low_bit + static_cast<int>(below(static_cast<std::uint64_t>(high_bit - low_bit + 1))));
  const std::uint64_t top = std::uint64_t{1} << bit;
  return top | (next() & (top - 1));
}

std::int64_t Rng::log_signed(int low_bit, int high_bit) noexcept {
  const std::uint64_t magnitude = log_magnitude(low_bit, high_bit);
  return with_sign(coin(), magnitude);
}

std::uint64_t stream_seed(std::uint64_t seed, std::string_view name) noexcept {
  // FNV-1a of the name, then one splitmix64 round so that nearby seeds give unrelated streams.
  std::uint64_t h = 0xCBF29CE484222325U;
  for (const char c : name) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001B3U;
  }
  Rng mix(seed ^ h);
  return mix.next();
}

std::int64_t with_sign(bool negative, std::uint64_t magnitude) noexcept {
  const auto value = static_cast<std::int64_t>(magnitude);
  return negative ? -value : value;
}

bool offset(std::int64_t raw, std::int64_t d, std::int64_t* out) noexcept {
  if (d > 0 && raw > raw_max - d) return false;
  if (d < 0 && raw < raw_min - d) return false;
  *out = raw + d;
  return true;
}

void add_around(ArgsList& list, std::int64_t center, std::int64_t radius) {
  for (std::int64_t d = -radius; d <= radius; ++d) {
    std::int64_t r = 0;
    if (offset(center, d, &r)) list.push_back({raw(r)});
  }
}

void add_sweep(ArgsList& list, std::int64_t center, int max_log2) {
  for (int j = 0; j <= max_log2 && j < 63; ++j) {
    const std::int64_t step = std::int64_t{1} << j;
    for (const std::int64_t d : {step, step - 1, step + 1}) {
      std::int64_t r = 0;
      if (offset(center, d, &r)) list.push_back({raw(r)});
      if (offset(center, -d, &r)) list.push_back({raw(r)});
    }
  }
}

void add_both_signs(ArgsList& list, std::int64_t value) {
  list.push_back({raw(value)});
  if (value != raw_min && value != 0) list.push_back({raw(-value)});
}

namespace {

void push_signed(std::vector<std::int64_t>& out, std::int64_t v) {
  out.push_back(v);
  if (v != 0 && v != raw_min) out.push_back(-v);
}

void finish(std::vector<std::int64_t>& out) {
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

}  // namespace

std::vector<std::int64_t> special_values() {
  std::vector<std::int64_t> out;
  for (const std::int64_t v :
       {std::int64_t{0}, std::int64_t{1}, std::int64_t{2}, std::int64_t{3}, raw_one / 2,
        raw_one / 2 - 1, raw_one / 2 + 1, raw_one - 1, raw_one, raw_one + 1, 2 * raw_one,
        3 * raw_one, 0x3243F6A89, 0x1921FB544, 0x6487ED511}) {
    push_signed(out, v);
  }
  for (int bit = 0; bit < 63; ++bit) {
    const std::int64_t p = std::int64_t{1} << bit;
    for (const std::int64_t v : {p - 1, p, p + 1})
      push_signed(out, v);
  }
  for (const std::int64_t v : {raw_max, raw_max - 1, raw_max - 2})
    push_signed(out, v);
  for (const std::int64_t v : {raw_min, raw_min + 1, raw_min + 2})
    out.push_back(v);
  finish(out);
  return out;
}

std::vector<std::int64_t> special_values_small() {
  std::vector<std::int64_t> out;
  for (const std::int64_t v :
       {std::int64_t{0}, std::int64_t{1}, std::int64_t{2}, std::int64_t{1} << 16, raw_one / 2,
        raw_one - 1, raw_one, raw_one + 1, 2 * raw_one, 3 * raw_one, 0x3243F6A89, raw_one << 15,
        raw_one << 16, raw_one << 30, raw_max, raw_max - 1}) {
    push_signed(out, v);
  }
  out.push_back(raw_min);
  out.push_back(raw_min + 1);
  finish(out);
  return out;
}

std::int64_t nearest_raw(mpfr_srcptr value) {
  Mp scratch(mpfr_get_prec(value) + 64);
  return round_to_fixed(value, scratch.get()).raw();
}

std::vector<HalfPiMultiple> half_pi_multiples() {
  // Work at 256 bits: k pi/2 for k < 2^31 must be right to far below one raw unit, and the
  // continued fraction below loses a few bits per term.
  constexpr mpfr_prec_t precision = 256;
  Mp step(precision);  // pi/2 in raw units: pi 2^31
  mpfr_const_pi(step.get(), MPFR_RNDN);
  mpfr_mul_2ui(step.get(), step.get(), 31, MPFR_RNDN);
  Mp scratch(precision);
  mpfr_set_ui_2exp(scratch.get(), 1, 63, MPFR_RNDN);
  mpfr_div(scratch.get(), scratch.get(), step.get(), MPFR_RNDN);
  const std::uint64_t k_max = mpfr_get_ui(scratch.get(), MPFR_RNDZ);

  std::vector<std::uint64_t> ks;
  for (std::uint64_t k = 0; k <= 512; ++k) {
    ks.push_back(k);
    ks.push_back(k_max - k);
  }
  for (int j = 1; j < 64 && (std::uint64_t{1} << j) <= k_max; ++j) {
    const std::uint64_t p = std::uint64_t{1} << j;
    for (const std::uint64_t k : {p - 1, p, p + 1})
      ks.push_back(k);
  }
  // The k with k pi 2^31 closest to an integer are the continued-fraction denominators of
  // pi 2^31 (best approximations) and their small multiples: there the Fixed input is nearest a
  // zero of sin or cos, so the range reduction must cancel the most bits.
  {
    Mp x(precision);
    Mp whole(precision);
    mpfr_set(x.get(), step.get(), MPFR_RNDN);
    std::uint64_t q_prev = 0;
    std::uint64_t q = 1;
    for (int term = 0; term < 40; ++term) {
      mpfr_frac(x.get(), x.get(), MPFR_RNDN);
      if (mpfr_zero_p(x.get()) != 0) break;
      mpfr_ui_div(x.get(), 1, x.get(), MPFR_RNDN);
      mpfr_floor(whole.get(), x.get());
      if (mpfr_cmp_ui(whole.get(), k_max) > 0) break;
      const std::uint64_t a = mpfr_get_ui(whole.get(), MPFR_RNDN);
      const wide::U128 next = wide::add(wide::Default::mul(a, q), wide::U128{0, q_prev});
      if (next.hi != 0 || next.lo > k_max) break;
      q_prev = q;
      q = next.lo;
      for (std::uint64_t m = 1; m <= 32 && q <= k_max / m; ++m)
        ks.push_back(m * q);
    }
  }
  Rng rng(0x6861'6C66'5069'2121U);
  for (int i = 0; i < 1000; ++i)
    ks.push_back(1 + rng.below(k_max));
  std::sort(ks.begin(), ks.end());
  ks.erase(std::unique(ks.begin(), ks.end()), ks.end());

  std::vector<HalfPiMultiple> out;
  out.reserve(ks.size());
  for (const std::uint64_t k : ks) {
    mpfr_mul_ui(scratch.get(), step.get(), k, MPFR_RNDN);
    mpfr_rint(scratch.get(), scratch.get(), MPFR_RNDN);
    if (mpfr_fits_intmax_p(scratch.get(), MPFR_RNDN) == 0) continue;
    out.push_back({k, static_cast<std::int64_t>(mpfr_get_sj(scratch.get(), MPFR_RNDN))});
  }
  return out;
}

}  // namespace detsim::accuracy::detail
