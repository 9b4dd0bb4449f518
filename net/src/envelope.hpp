// A compressed envelope: what the rejoin snapshot (snapshot.cpp) and the server's snapshots
// (server_snapshot.cpp) put their payloads in before they go on the wire.
//
//     magic (4 bytes, the caller's) | compression u8 (0: none, 1: zstd) | size u64 (of the payload
//     uncompressed) | payload, compressed or not
//
// zstd (Debian's libzstd) at the caller's level (3 by default) with its frame checksum, so bytes
// altered on the way fail to decompress instead of loading; a build without zstd writes the payload
// as it is and refuses a compressed one with a clear error.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <detsim/core/status.hpp>

namespace detsim::net::detail {

using EnvelopeMagic = std::array<std::uint8_t, 4>;

/// The envelope around `payload`: zstd-compressed where the build has zstd and `compress` says so
/// (and compression succeeds), else stored. With a `prefix` (bytes the reader holds too, such as
/// an earlier state), zstd refers to it as to bytes just before the payload: what the payload
/// repeats of it costs a few bytes a run, wherever it moved to (a delta that survives shifts).
/// `level`: zstd's compression level (3, its default: about a millisecond for a 100 KB state).
[[nodiscard]] std::vector<std::uint8_t> seal_envelope(const EnvelopeMagic& magic,
                                                      std::span<const std::uint8_t> payload,
                                                      bool compress = true,
                                                      std::span<const std::uint8_t> prefix = {},
                                                      int level = 3);

/// The payload of an envelope with `magic`, at most `max_payload` bytes uncompressed whatever the
/// header says; errors say what is wrong ("not a ... (no DSNP header)", "corrupt", ...), with
/// `what` naming the thing ("snapshot"). `prefix`: the one the writer sealed it with.
[[nodiscard]] Expected<std::vector<std::uint8_t>> open_envelope(
    const EnvelopeMagic& magic, std::span<const std::uint8_t> bytes, std::size_t max_payload,
    const char* what, std::span<const std::uint8_t> prefix = {});

}  // namespace detsim::net::detail
