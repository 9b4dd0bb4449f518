#include <detsim/core/bytes.hpp>

namespace detsim {

std::string ByteReader::error() const {
  if (ok_) return {};
  return "byte " + std::to_string(error_offset_) + ": " + error_detail();
}

std::string ByteReader::error_detail() const {
  if (ok_) return {};
  return std::string(error_what_) + ": expected " + error_expected_;
}

}  // namespace detsim
