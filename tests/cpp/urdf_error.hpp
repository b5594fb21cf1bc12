#pragma once
// The URDF reader's refusal of a document, for the tests of its messages (test_urdf.cpp) and of
// its robustness (test_parser_fuzz.cpp).
#include <stdexcept>
#include <string>

#include "mechbal/io/urdf.hpp"

namespace mechbal::test {

/// The message of the std::invalid_argument model_from_urdf_string throws on `xml`, or
/// "no error" when it reads the document.
inline std::string urdf_error_of(const std::string& xml) {
  try {
    model_from_urdf_string(xml);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace mechbal::test
