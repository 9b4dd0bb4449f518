#include "output.hpp"

#include <detsim_tools/json_text.hpp>

#include <cinttypes>
#include <cstdio>

#if __has_include(<unistd.h>)
#include <unistd.h>
#define DETSIM_HAVE_ISATTY 1
#else
#define DETSIM_HAVE_ISATTY 0
#endif

namespace detsim::cli {

std::string hex(std::uint64_t v) {
  char text[17];
  std::snprintf(text, sizeof text, "%016" PRIx64, v);
  return text;
}

bool write_file(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return false;
  const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  return std::fclose(f) == 0 && ok;
}

namespace {
std::string& program() {
  static std::string name = "detsim";
  return name;
}
}  // namespace

void set_program_name(std::string_view name) {
  program() = std::string(name);
}

const std::string& program_name() {
  return program();
}

int usage_error(std::string_view command, const std::string& message) {
  std::fprintf(stderr, "%s %.*s: %s\n", program().c_str(), static_cast<int>(command.size()),
               command.data(), message.c_str());
  return exit_usage;
}

std::string Json::quote(std::string_view s) {
  return tools::json_quote(s);
}

std::string Json::array(const std::vector<std::string>& json_values) {
  std::string out = "[";
  for (std::size_t i = 0; i < json_values.size(); ++i) {
    if (i != 0) out += ",";
    out += json_values[i];
  }
  return out + "]";
}

void Json::key(std::string_view k) {
  if (!body_.empty()) body_ += ",";
  body_ += quote(k) + ":";
}

Json& Json::str(std::string_view k, std::string_view value) {
  key(k);
  body_ += quote(value);
  return *this;
}

Json& Json::num(std::string_view k, std::uint64_t value) {
  key(k);
  body_ += std::to_string(value);
  return *this;
}

Json& Json::real(std::string_view k, double value) {
  key(k);
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  body_ += text;
  return *this;
}

Json& Json::boolean(std::string_view k, bool value) {
  key(k);
  body_ += value ? "true" : "false";
  return *this;
}

Json& Json::null(std::string_view k) {
  key(k);
  body_ += "null";
  return *this;
}

Json& Json::frame(std::string_view k, std::optional<std::uint64_t> value) {
  return value ? num(k, *value) : null(k);
}

Json& Json::raw(std::string_view k, const std::string& json) {
  key(k);
  body_ += json;
  return *this;
}

void Json::print() const {
  const std::string t = text();
  std::fwrite(t.data(), 1, t.size(), stdout);
  std::fputc('\n', stdout);
}

Progress::Progress(std::string label)
    : label_(std::move(label)), start_(std::chrono::steady_clock::now()), last_draw_(start_) {
#if DETSIM_HAVE_ISATTY
  terminal_ = isatty(STDERR_FILENO) != 0;
#endif
}

Progress::~Progress() {
  done();
}

void Progress::update(std::uint64_t done_count, std::uint64_t total) {
  if (!terminal_ || total == 0) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - start_ < std::chrono::seconds(1)) return;
  if (drawn_ && now - last_draw_ < std::chrono::milliseconds(100) && done_count != total) return;
  last_draw_ = now;
  constexpr int width = 30;
  const auto filled =
      static_cast<int>(static_cast<double>(done_count) / static_cast<double>(total) * width);
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(width, '.');
  std::fprintf(stderr, "\r%s [%s] %" PRIu64 "/%" PRIu64, label_.c_str(), bar.c_str(), done_count,
               total);
  std::fflush(stderr);
  drawn_ = true;
}

void Progress::done() {
  if (!drawn_) return;
  std::fputs("\r\033[K", stderr);
  std::fflush(stderr);
  drawn_ = false;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace detsim::cli
