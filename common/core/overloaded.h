// The "overloaded" idiom for std::visit: a visitor built from lambdas.
#pragma once

namespace skyfarm {

template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

}  // namespace skyfarm
