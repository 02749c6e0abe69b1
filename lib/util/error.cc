#include "util/error.h"

namespace dgmm {

InputError::InputError(const std::string& message) : std::runtime_error(message) {}

InputError MakeInputError(const std::string& file, const std::string& field,
                          const std::string& problem) {
  std::string message;
  for (const std::string* part : {&file, &field, &problem}) {
    if (part->empty()) continue;
    if (!message.empty()) message += ": ";
    message += *part;
  }
  return InputError(message);
}

}  // namespace dgmm
