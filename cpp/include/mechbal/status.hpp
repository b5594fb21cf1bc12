#pragma once
/// \file status.hpp
/// Status values returned by real-time algorithms (docs/architecture.md: algorithms never throw).
#include <cstdint>

namespace mechbal {

/// Bit flags: several conditions can hold at once (e.g. saturated and near-singular).
enum class Status : std::uint32_t {
  ok = 0,
  non_finite_input = 1u << 0,  ///< an input was NaN or infinite: output holds the last safe value
  singular = 1u << 1,          ///< a matrix was (near) singular: damped solution used
  saturated = 1u << 2,         ///< an output hit its configured limit and was clipped
  bad_size = 1u << 3,          ///< an input had the wrong dimension: output left untouched
  solver_error = 1u << 4,      ///< an underlying solver (e.g. KDL) reported an error
  /// an input was finite but outside its documented range or configured limit (e.g. a wrist
  /// momentum above ReactionlessWristConfig::max_momentum, a joint speed above max_speed), or a
  /// finite input overflowed to a non-finite result: output holds the last safe value (a batch
  /// instant gets zeros)
  out_of_range = 1u << 5,
};

constexpr Status operator|(Status a, Status b) noexcept {
  return static_cast<Status>(static_cast<std::uint32_t>(a) | static_cast<std::uint32_t>(b));
}
constexpr Status& operator|=(Status& a, Status b) noexcept { return a = a | b; }
constexpr bool has(Status s, Status flag) noexcept {
  return (static_cast<std::uint32_t>(s) & static_cast<std::uint32_t>(flag)) != 0u;
}
constexpr bool is_ok(Status s) noexcept { return s == Status::ok; }

/// Human-readable name of the flags set in `s` (static storage, no allocation).
const char* status_name(Status s) noexcept;

}  // namespace mechbal
