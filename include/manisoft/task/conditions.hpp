// Named conditions of a task's success predicate (as ManiSkill's evaluate() returns a dict of
// named booleans): every task's predicate is the conjunction of a few named conditions (COLL:
// inside, touching_container, off_table, released, at_rest), so a failed episode is explained
// by the conditions that did not hold at its last step. Fixed capacity: no heap allocation.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <string_view>

#include "manisoft/core/error.hpp"

namespace manisoft::task {

struct Condition {
  std::string_view name;
  bool holds = false;
};

class Conditions {
 public:
  static constexpr std::size_t capacity = 8;

  /// Adds a condition; returns *this for chaining.
  Conditions& add(std::string_view name, bool holds) {
    if (count_ == capacity) ::manisoft::detail::fail("Conditions: more than ", capacity, " conditions (adding '", name, "')");
    items_[count_++] = Condition{name, holds};
    return *this;
  }

  /// The predicate: every condition holds (false when there are none).
  bool all() const {
    if (count_ == 0) return false;
    for (std::size_t i = 0; i < count_; ++i)
      if (!items_[i].holds) return false;
    return true;
  }
  /// Whether the named condition is listed and holds.
  bool holds(std::string_view name) const {
    for (std::size_t i = 0; i < count_; ++i)
      if (items_[i].name == name) return items_[i].holds;
    ::manisoft::detail::fail("Conditions: no condition named '", name, "'");
  }
  /// The names of the conditions that do not hold, comma-separated ("" when all hold).
  std::string unmet() const { return names_where(false); }
  /// The names of the conditions that hold, comma-separated.
  std::string met() const { return names_where(true); }

  std::size_t size() const { return count_; }
  const Condition* begin() const { return items_.data(); }
  const Condition* end() const { return items_.data() + count_; }

 private:
  std::string names_where(bool holds) const {
    std::string out;
    for (std::size_t i = 0; i < count_; ++i)
      if (items_[i].holds == holds) out += (out.empty() ? "" : ", ") + std::string(items_[i].name);
    return out;
  }

  std::array<Condition, capacity> items_{};
  std::size_t count_ = 0;
};

}  // namespace manisoft::task
