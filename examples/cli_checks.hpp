// Command-line checks shared by the example programs (CLI11): validators whose messages name the
// limit and the value as typed, and an error printer that puts the flag in front, so a refusal
// reads "--path-speed must be > 0 (got 0)" or "--index must be >= 0 (got -1)". A validator sees
// the text before CLI11 converts it, so a negative count is refused before it could wrap around
// in an unsigned variable, and "nan" or "inf" before any range comparison (which NaN would pass).
#pragma once

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <string>

namespace manisoft::cli {

namespace detail {

inline std::string number_text(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", v);
  return buffer;
}

/// "" when `text` is a finite number within the bounds, else the reason (the value as typed).
inline std::string check_number(const std::string& text, double low, bool low_open, double high, bool high_open) {
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size()) return "expects a number (got '" + text + "')";
  if (!std::isfinite(v) || errno == ERANGE) return "must be a finite number (got " + text + ")";
  const bool has_low = std::isfinite(low), has_high = std::isfinite(high);
  const bool below = has_low && (low_open ? !(v > low) : !(v >= low));
  const bool above = has_high && (high_open ? !(v < high) : !(v <= high));
  if (!below && !above) return "";
  std::string limit;
  if (has_low && has_high)
    limit = "in " + std::string(low_open ? "(" : "[") + number_text(low) + ", " + number_text(high) + (high_open ? ")" : "]");
  else if (has_low)
    limit = (low_open ? "> " : ">= ") + number_text(low);
  else
    limit = (high_open ? "< " : "<= ") + number_text(high);
  return "must be " + limit + " (got " + text + ")";
}

inline CLI::Validator bounds(double low, bool low_open, double high, bool high_open, const std::string& description) {
  return CLI::Validator([=](std::string& text) { return check_number(text, low, low_open, high, high_open); }, description);
}

inline constexpr double none = HUGE_VAL;

}  // namespace detail

/// value > low
inline CLI::Validator above(double low) { return detail::bounds(low, true, detail::none, false, "> " + detail::number_text(low)); }
/// value >= low
inline CLI::Validator at_least(double low) { return detail::bounds(low, false, detail::none, false, ">= " + detail::number_text(low)); }
/// low <= value <= high
inline CLI::Validator between(double low, double high) {
  return detail::bounds(low, false, high, false, "in [" + detail::number_text(low) + ", " + detail::number_text(high) + "]");
}
/// low < value <= high
inline CLI::Validator above_at_most(double low, double high) {
  return detail::bounds(low, true, high, false, "in (" + detail::number_text(low) + ", " + detail::number_text(high) + "]");
}
inline CLI::Validator positive() { return above(0); }
inline CLI::Validator non_negative() { return at_least(0); }

/// The count and seed options `names` (unsigned integers, where a negative value would wrap
/// around) refuse a negative value with "--index must be >= 0 (got -1)". Give them no CLI11
/// NonNegativeNumber check of their own: its message would come first.
inline void check_counts(CLI::App& app, std::initializer_list<const char*> names) {
  for (const char* name : names) app.get_option(name)->check(non_negative());
}

/// Error messages as "program: --flag must be > 0 (got 0)" (CLI11 writes "--flag: must be ..."),
/// followed by the pointer to --help.
inline void readable_errors(CLI::App& app, const std::string& program) {
  app.failure_message([program](const CLI::App* a, const CLI::Error& e) {
    std::string message = e.what();
    const auto colon = message.find(": must ");
    if (colon != std::string::npos) message.erase(colon, 1);
    const auto expects = message.find(": expects ");
    if (expects != std::string::npos) message.erase(expects, 1);
    return program + ": " + message + "\n" + (a->get_help_ptr() ? "Run with --help for more information.\n" : "");
  });
}

/// Parses the command line: -1 to go on, else the exit code, the message printed (0 after --help,
/// 2 after a bad flag, the code of every program here; CLI11_PARSE would return CLI11's own codes,
/// 100 and above).
inline int parse(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
    return -1;
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
}

}  // namespace manisoft::cli
