#pragma once
// Shared by the libFuzzer harnesses: the input bytes as a file (the readers take paths) on a
// per-process path in /dev/shm (or /tmp), and HDF5's error printing off.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace dgmm::fuzz {

inline std::string InputPath(const char* extension) {
  const std::filesystem::path dir =
      std::filesystem::exists("/dev/shm") ? "/dev/shm" : std::filesystem::temp_directory_path();
  return (dir / ("dgmm-fuzz-" + std::to_string(::getpid()) + extension)).string();
}

inline std::string WriteInput(const uint8_t* data, size_t size, const char* extension) {
  const std::string path = InputPath(extension);
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

}  // namespace dgmm::fuzz
