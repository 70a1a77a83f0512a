// Errors as values for bad input (files, network, command lines): a Result<T> holds either a value
// or an Error whose message names what is wrong and where ("file:line: reason"). Broken internal
// contracts are bugs and assert instead.
#pragma once

#include <cassert>
#include <string>
#include <utility>
#include <variant>

namespace duet {

struct Error {
  std::string message;
};

// Builds "file:line: reason" (line omitted when 0).
Error make_error(const std::string& file, int line, const std::string& reason);

template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : data_(std::move(value)) {}  // NOLINT: implicit on purpose
  Result(Error error) : data_(std::move(error)) {}  // NOLINT

  bool ok() const { return data_.index() == 0; }
  explicit operator bool() const { return ok(); }

  T& value() & {
    assert(ok());
    return std::get<0>(data_);
  }
  const T& value() const& {
    assert(ok());
    return std::get<0>(data_);
  }
  T&& value() && {
    assert(ok());
    return std::get<0>(std::move(data_));
  }
  const Error& error() const {
    assert(!ok());
    return std::get<1>(data_);
  }

 private:
  std::variant<T, Error> data_;
};

// For operations that produce no value.
struct Ok {};
using Status = Result<Ok>;

}  // namespace duet
