// Bad input from a user (a file, a config key, an option): the message names the file, line or
// key and what was expected. The CLI prints it as one line; a batch records it against the file.
#pragma once

#include <stdexcept>
#include <string>

namespace bifilar {

class UserError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace bifilar
