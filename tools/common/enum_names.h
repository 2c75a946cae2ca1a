#pragma once
// The names of an enum's values, for the Name/FromName pair every choice option has (the
// spelling on the command line and in files): one table per enum, read both ways.

#include <cstddef>
#include <optional>
#include <string_view>
#include <utility>

namespace igi {

template <typename E, size_t N>
struct EnumNames {
  std::pair<E, std::string_view> entries[N];

  // The name of `value`; "?" for a value not in the table.
  constexpr std::string_view Name(E value) const {
    for (const auto& [v, name] : entries) {
      if (v == value) return name;
    }
    return "?";
  }
  // The value `name` spells; nullopt for any other text.
  constexpr std::optional<E> FromName(std::string_view name) const {
    for (const auto& [v, n] : entries) {
      if (n == name) return v;
    }
    return std::nullopt;
  }
};

}  // namespace igi
