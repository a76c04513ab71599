/// \file policy.hpp
/// Policy kinds. Every policy type declares `using policy_kind = kind::<axis>;` so that
/// a stepper can be composed from an unordered list of policy values
/// (`fluid::solver s{grid, bc, flux::hllc{}, recon::muscl<limiter::mc>{}}`) and every
/// axis left out takes its default. Passing two policies of one kind, or a value that
/// is not a policy, is a compile error with a sentence.
#pragma once
#include <tuple>
#include <type_traits>

namespace parafsi {
namespace kind {
struct gas {};
struct flux {};
struct reconstruction {};
struct turbulence {};
struct viscosity {};
struct frame {};
struct time {};
}  // namespace kind

template <class T>
concept policy = requires {
  typename std::remove_cvref_t<T>::policy_kind;
};

template <class Kind, class T>
inline constexpr bool is_kind_v = std::is_same_v<typename std::remove_cvref_t<T>::policy_kind, Kind>;

namespace detail {
template <class Kind, class Default, class... Ps>
struct pick;
template <class Kind, class Default>
struct pick<Kind, Default> {
  using type = Default;
};
template <class Kind, class Default, class P, class... Ps>
struct pick<Kind, Default, P, Ps...> {
  using type =
      std::conditional_t<is_kind_v<Kind, P>, std::remove_cvref_t<P>, typename pick<Kind, Default, Ps...>::type>;
};
}  // namespace detail

/// The policy of kind Kind among Ps (Default if none).
template <class Kind, class Default, class... Ps>
using pick_t = typename detail::pick<Kind, Default, Ps...>::type;

template <class Kind, class... Ps>
inline constexpr int count_kind_v = (0 + ... + int(is_kind_v<Kind, Ps>));

/// The value of kind Kind among args (a default-constructed Default if none).
template <class Kind, class Default, class... Ps>
constexpr auto pick_value(const Ps&... args) {
  using T = pick_t<Kind, Default, Ps...>;
  if constexpr (count_kind_v<Kind, Ps...> == 0) {
    return Default{};
  } else {
    T out{};
    ((void)([&] {
       if constexpr (is_kind_v<Kind, Ps>) out = args;
     }()),
     ...);
    return out;
  }
}

}  // namespace parafsi
