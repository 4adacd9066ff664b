// Dispatch over a variant of scene element kinds (OccluderShape, BeamShape):
// each alternative is a struct with `static constexpr std::string_view kType`,
// its "type" in scene JSON. Included by the kinds' registries (.cpp files).
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "protocol/json_reader.hpp"

namespace beamcast {

// A kind the service makes itself and clients never write (a light kind with
// `static constexpr bool kDerived = true`: the light of an emitting beam):
// left out of the "type" lists and of parsing.
template <class K>
constexpr bool is_derived_kind() {
  if constexpr (requires { K::kDerived; }) {
    return K::kDerived;
  } else {
    return false;
  }
}

// Calls f(std::type_identity<K>{}) for every alternative K of Variant, in order.
template <class Variant, class F>
void each_kind(F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (f(std::type_identity<std::variant_alternative_t<I, Variant>>{}), ...);
  }(std::make_index_sequence<std::variant_size_v<Variant>>{});
}

// The "type" strings of every alternative, in the variant's order.
template <class Variant>
std::vector<std::string_view> kind_types() {
  std::vector<std::string_view> types;
  each_kind<Variant>([&](auto kind) {
    using K = typename decltype(kind)::type;
    if constexpr (!is_derived_kind<K>()) types.push_back(K::kType);
  });
  return types;
}

// The alternative K whose kType is the string at `type`, made by
// make(std::type_identity<K>{}); an unknown type throws invalid_value at
// type.path, listing the types.
template <class Variant, class Make>
Variant parse_kind(const json_read::Node& type, Make&& make) {
  const std::string name = json_read::read_string(type);
  // On the heap: GCC 12 cannot see that a std::optional<Variant> holding a
  // kind it never emplaces is set before the move (-Wmaybe-uninitialized).
  std::unique_ptr<Variant> shape;
  each_kind<Variant>([&](auto kind) {
    using K = typename decltype(kind)::type;
    if constexpr (!is_derived_kind<K>()) {
      if (!shape && name == K::kType) shape = std::make_unique<Variant>(make(kind));
    }
  });
  if (shape) return std::move(*shape);
  std::string allowed;
  for (std::string_view t : kind_types<Variant>()) {
    if (!allowed.empty()) allowed += ", ";
    allowed += '"';
    allowed += t;
    allowed += '"';
  }
  json_read::fail("invalid_value", type.path,
                  type.name() + " must be one of " + allowed + ", got " +
                      json_read::describe(type.json()));
}

}  // namespace beamcast
