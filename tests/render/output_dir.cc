#include "tests/render/output_dir.h"

#include <unistd.h>

#include <system_error>

namespace dgmm::test {
namespace {

// The folder, removed by its destructor at exit (a function-local static).
class ProcessFolder {
 public:
  ProcessFolder()
      : path_(std::filesystem::temp_directory_path() / ("dgmm-render-tests-" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path_);
  }
  ~ProcessFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ProcessFolder(const ProcessFolder&) = delete;
  ProcessFolder& operator=(const ProcessFolder&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace

std::filesystem::path OutputPath(const std::string& name) {
  static const ProcessFolder folder;
  return folder.path() / name;
}

}  // namespace dgmm::test
