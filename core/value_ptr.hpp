// An owning pointer that copies its object when it is copied, so a class holding an optional,
// rarely used part on the heap keeps its value semantics (Chip and its Axis).
#pragma once

#include <memory>
#include <utility>

namespace l6470emu {

/// Owns at most one T; copying copies the T. Empty by default.
template <class T>
class ValuePtr {
 public:
  ValuePtr() = default;
  explicit ValuePtr(std::unique_ptr<T> p) : p_(std::move(p)) {}
  ValuePtr(const ValuePtr& o) : p_(o.p_ ? std::make_unique<T>(*o.p_) : nullptr) {}
  ValuePtr(ValuePtr&&) noexcept = default;
  ValuePtr& operator=(const ValuePtr& o) {
    if (this != &o) p_ = o.p_ ? std::make_unique<T>(*o.p_) : nullptr;
    return *this;
  }
  ValuePtr& operator=(ValuePtr&&) noexcept = default;

  explicit operator bool() const { return p_ != nullptr; }
  T* get() const { return p_.get(); }
  T* operator->() const { return p_.get(); }
  T& operator*() const { return *p_; }
  void reset() { p_.reset(); }

 private:
  std::unique_ptr<T> p_;
};

}  // namespace l6470emu
