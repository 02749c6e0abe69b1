#pragma once
// Errors caused by the user's input (files, flags, values). The app prints what() as one
// line and exits non-zero; programmer mistakes use assert instead.
#include <stdexcept>
#include <string>

namespace dgmm {

// A problem with user input; what() is one line naming the file, the field and what was expected.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message);
};

// InputError whose message is "<file>: <field>: <problem>" (parts left empty are skipped).
InputError MakeInputError(const std::string& file, const std::string& field,
                          const std::string& problem);

}  // namespace dgmm
