// What every detsim subcommand shares: exit codes, one JSON object on stdout, hashes as 16 hex
// digits, and a progress bar on stderr (only when stderr is a terminal and the work has taken more
// than a second).
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace detsim::cli {

inline constexpr int exit_ok = 0;
inline constexpr int exit_check_failed = 1;  ///< a hash mismatch, a desync, a failed check
inline constexpr int exit_usage = 2;         ///< bad usage or bad input (message on stderr)

/// 16 lowercase hex digits.
std::string hex(std::uint64_t v);

/// Writes `bytes` to the file `path` (replacing it); false when it cannot.
bool write_file(const std::string& path, const std::vector<std::uint8_t>& bytes);

/// The tool's name in messages: "detsim", or what a game's tool passed to run_cli.
void set_program_name(std::string_view name);
[[nodiscard]] const std::string& program_name();

/// Prints "<program> <command>: <message>" on stderr and returns exit_usage.
int usage_error(std::string_view command, const std::string& message);

/// A JSON object built field by field, printed once.
class Json {
 public:
  Json& str(std::string_view key, std::string_view value);
  Json& num(std::string_view key, std::uint64_t value);
  Json& real(std::string_view key, double value);
  Json& boolean(std::string_view key, bool value);
  Json& null(std::string_view key);
  Json& hash(std::string_view key, std::uint64_t value) { return str(key, hex(value)); }
  /// A frame number or null.
  Json& frame(std::string_view key, std::optional<std::uint64_t> value);
  /// A value already in JSON (an object or an array built with another Json / array()).
  Json& raw(std::string_view key, const std::string& json);
  [[nodiscard]] std::string text() const { return "{" + body_ + "}"; }
  /// Prints the object and a newline on stdout.
  void print() const;

  static std::string quote(std::string_view s);
  static std::string array(const std::vector<std::string>& json_values);

 private:
  void key(std::string_view k);
  std::string body_;
};

/// A progress bar on stderr: drawn only when stderr is a terminal, and only once the work has
/// taken more than a second; erased by done() or the destructor.
class Progress {
 public:
  explicit Progress(std::string label);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  void update(std::uint64_t done, std::uint64_t total);
  void done();

 private:
  std::string label_;
  bool terminal_ = false;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

/// Seconds since `start`, for reports.
double seconds_since(std::chrono::steady_clock::time_point start);

}  // namespace detsim::cli
