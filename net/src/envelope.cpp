// The compressed envelope (envelope.hpp).
#include "envelope.hpp"

#include "wire.hpp"

#include <algorithm>
#include <string>

#if DETSIM_WITH_ZSTD
#include <zstd.h>
#endif

namespace detsim::net::detail {
namespace {

constexpr std::size_t envelope_size = 4 + 1 + 8;
constexpr std::uint8_t uncompressed = 0;
constexpr std::uint8_t zstd_compressed = 1;

using wire::put;

std::uint64_t envelope_get(std::span<const std::uint8_t> bytes, std::size_t at, std::size_t n) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < n; ++i)
    v |= std::uint64_t{bytes[at + i]} << (8 * i);
  return v;
}

std::vector<std::uint8_t> stored(const EnvelopeMagic& magic,
                                 std::span<const std::uint8_t> payload) {
  std::vector<std::uint8_t> out(magic.begin(), magic.end());
  out.push_back(uncompressed);
  put(out, payload.size(), 8);
  out.insert(out.end(), payload.begin(), payload.end());
  return out;
}

}  // namespace

std::vector<std::uint8_t> seal_envelope(const EnvelopeMagic& magic,
                                        std::span<const std::uint8_t> payload, bool compress,
                                        std::span<const std::uint8_t> prefix, int level) {
#if DETSIM_WITH_ZSTD
  if (!compress) return stored(magic, payload);
  std::vector<std::uint8_t> out(magic.begin(), magic.end());
  out.push_back(zstd_compressed);
  put(out, payload.size(), 8);
  const std::size_t bound = ZSTD_compressBound(payload.size());
  out.resize(envelope_size + bound);
  // With the frame's checksum, so an envelope altered on the way fails to decompress instead of
  // loading.
  ZSTD_CCtx* context = ZSTD_createCCtx();
  std::size_t written = 1;
  if (context != nullptr) {
    ZSTD_CCtx_setParameter(context, ZSTD_c_compressionLevel, level);
    ZSTD_CCtx_setParameter(context, ZSTD_c_checksumFlag, 1);
    if (!prefix.empty()) ZSTD_CCtx_refPrefix(context, prefix.data(), prefix.size());
    written =
        ZSTD_compress2(context, out.data() + envelope_size, bound, payload.data(), payload.size());
    ZSTD_freeCCtx(context);
  }
  if (context != nullptr && !ZSTD_isError(written)) {
    out.resize(envelope_size + written);
    return out;
  }
  // Out of memory, or a zstd error: stored then.
#else
  (void)compress;
  (void)prefix;
  (void)level;
#endif
  return stored(magic, payload);
}

Expected<std::vector<std::uint8_t>> open_envelope(const EnvelopeMagic& magic,
                                                  std::span<const std::uint8_t> bytes,
                                                  std::size_t max_payload, const char* what,
                                                  std::span<const std::uint8_t> prefix) {
  const std::string name = what;
  if (bytes.size() < envelope_size || !std::equal(magic.begin(), magic.end(), bytes.begin()))
    return Status::error("not a " + name + " (no " + std::string(magic.begin(), magic.end()) +
                         " header)");
  const std::uint64_t compression = envelope_get(bytes, 4, 1);
  const std::uint64_t size = envelope_get(bytes, 5, 8);
  if (size > max_payload)
    return Status::error(name + " payload of " + std::to_string(size) +
                         " bytes is over the limit of " + std::to_string(max_payload));
  const std::span<const std::uint8_t> body = bytes.subspan(envelope_size);
  std::vector<std::uint8_t> payload;
  if (compression == uncompressed) {
    if (body.size() != size) return Status::error(name + " payload size differs from its header");
    payload.assign(body.begin(), body.end());
    return payload;
  }
  if (compression != zstd_compressed)
    return Status::error(name + ": unknown compression " + std::to_string(compression));
#if DETSIM_WITH_ZSTD
  const unsigned long long content = ZSTD_getFrameContentSize(body.data(), body.size());
  if (content != size)
    return Status::error(name + " compressed payload size differs from its header");
  payload.resize(static_cast<std::size_t>(size));
  ZSTD_DCtx* context = ZSTD_createDCtx();
  if (context == nullptr) return Status::error(name + ": out of memory to decompress");
  if (!prefix.empty()) ZSTD_DCtx_refPrefix(context, prefix.data(), prefix.size());
  const std::size_t got =
      ZSTD_decompressDCtx(context, payload.data(), payload.size(), body.data(), body.size());
  ZSTD_freeDCtx(context);
  if (ZSTD_isError(got) || got != size)
    return Status::error(name + " compressed payload does not decompress (corrupt)");
  return payload;
#else
  (void)prefix;
  return Status::error(name + " is compressed with zstd, and this build has no zstd " +
                       "(DETSIM_WITH_ZSTD=OFF)");
#endif
}

}  // namespace detsim::net::detail
