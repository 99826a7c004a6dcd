#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

namespace csgrt {

/// Thrown when a shape, transform or structure is given a parameter it cannot use. The message
/// names the thing, the parameter and the value: "Sphere: radius must be > 0 and finite, got -1".
class InvalidParameter : public std::invalid_argument {
public:
    /// An error whose message names no single parameter (parameter() is empty).
    explicit InvalidParameter(const std::string& message) : std::invalid_argument(message) {}
    /// An error about `parameter` ("radius", "phi_max", "name"): callers such as the scene
    /// loader point at the key of that name without parsing the message.
    InvalidParameter(const std::string& message, std::string parameter)
        : std::invalid_argument(message), parameter_(std::move(parameter)) {}

    /// The parameter the error is about, as the thrower named it; empty when none was named.
    const std::string& parameter() const { return parameter_; }

private:
    std::string parameter_;
};

namespace detail {
template <class Value>
std::string describe(const Value& value) {
    std::ostringstream out;
    out.precision(17);
    if constexpr (std::is_base_of_v<Eigen::DenseBase<Value>, Value>) {
        out << '(';
        for (Eigen::Index i = 0; i < value.size(); ++i) out << (i ? ", " : "") << value(i);
        out << ')';
    } else {
        out << value;
    }
    return out.str();
}
}  // namespace detail

/// Throws InvalidParameter "`what`: `parameter` must be `expectation`, got `value`" unless ok.
template <class Value>
void require(bool ok, std::string_view what, std::string_view parameter,
             std::string_view expectation, const Value& value) {
    if (ok) return;
    std::string message;
    message.append(what).append(": ").append(parameter).append(" must be ");
    message.append(expectation).append(", got ").append(detail::describe(value));
    throw InvalidParameter(message, std::string(parameter));
}

/// `require` for the common case of a strictly positive, finite length.
inline void require_positive(double value, std::string_view what, std::string_view parameter) {
    require(value > 0.0 && value < std::numeric_limits<double>::infinity(), what, parameter,
            "> 0 and finite", value);
}

/// `require` for a value that may be any finite number.
inline void require_finite(double value, std::string_view what, std::string_view parameter) {
    require(std::isfinite(value), what, parameter, "finite", value);
}

/// `require` for a vector whose components may be any finite numbers.
template <class Derived>
void require_finite(const Eigen::MatrixBase<Derived>& value, std::string_view what,
                    std::string_view parameter) {
    require(value.allFinite(), what, parameter, "finite", value.eval());
}

}  // namespace csgrt
