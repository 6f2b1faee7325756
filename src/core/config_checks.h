// The check behind every validate() of the core's configs and inputs (internal to the core).
#pragma once

#include <string>
#include <string_view>

#include "mvog/config.h"

namespace mvog {
namespace detail {

/// Throws ConfigError "FIELD: REASON", the message every validation gives.
[[noreturn]] inline void invalidField(const char* field, std::string_view reason) {
  throw ConfigError(std::string(field) + ": " + std::string(reason));
}

/// invalidField(field, reason) unless `condition` holds.
inline void require(bool condition, const char* field, std::string_view reason) {
  if (!condition) invalidField(field, reason);
}

}  // namespace detail
}  // namespace mvog
