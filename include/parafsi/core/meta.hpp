/// \file meta.hpp
/// Tiny type-list utilities: list, contains, index_of, append_unique (set union).
#pragma once
#include <cstddef>
#include <type_traits>

namespace parafsi::meta {

template <class... Ts>
struct list {
  static constexpr std::size_t size = sizeof...(Ts);
};

/// contains_v<T, list<...>>: true when T is one of the list's types.
template <class T, class L>
struct contains;
template <class T, class... Ts>
struct contains<T, list<Ts...>> : std::bool_constant<(std::is_same_v<T, Ts> || ...)> {};
template <class T, class L>
inline constexpr bool contains_v = contains<T, L>::value;

/// index_of_v<T, list<...>>: position of T in the list (compile error if absent).
template <class T, class L>
struct index_of;
template <class T, class... Ts>
struct index_of<T, list<T, Ts...>> : std::integral_constant<std::size_t, 0> {};
template <class T, class U, class... Ts>
struct index_of<T, list<U, Ts...>> : std::integral_constant<std::size_t, 1 + index_of<T, list<Ts...>>::value> {};
template <class T, class L>
inline constexpr std::size_t index_of_v = index_of<T, L>::value;

/// push_unique_t<L, T>: L with T appended unless already present.
template <class L, class T>
struct push_unique;
template <class T, class... Ts>
struct push_unique<list<Ts...>, T> {
  using type = std::conditional_t<contains_v<T, list<Ts...>>, list<Ts...>, list<Ts..., T>>;
};
template <class L, class T>
using push_unique_t = typename push_unique<L, T>::type;

/// union_t<L1, L2, ...>: the set union of several lists, first-seen order.
template <class... Ls>
struct union_of;
template <>
struct union_of<> {
  using type = list<>;
};
template <class L>
struct union_of<L> {
  using type = typename union_of<list<>, L>::type;
};
template <class... As>
struct union_of<list<As...>, list<>> {
  using type = list<As...>;
};
template <class... As, class B, class... Bs>
struct union_of<list<As...>, list<B, Bs...>> {
  using type = typename union_of<push_unique_t<list<As...>, B>, list<Bs...>>::type;
};
template <class L1, class L2, class L3, class... Ls>
struct union_of<L1, L2, L3, Ls...> {
  using type = typename union_of<typename union_of<L1, L2>::type, L3, Ls...>::type;
};
template <class... Ls>
using union_t = typename union_of<Ls...>::type;

/// Apply f.template operator()<T>() for every T of a list, in order.
template <class... Ts, class F>
constexpr void for_each_type(list<Ts...>, F&& f) {
  (f.template operator()<Ts>(), ...);
}

}  // namespace parafsi::meta
