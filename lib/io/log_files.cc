#include "io/log_files.h"

#include <glob.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>
#include <memory>

#include "util/error.h"

namespace dgmm {
namespace {

namespace fs = std::filesystem;

bool IsGlob(const std::string& path) { return path.find_first_of("*?[{") != std::string::npos; }

std::vector<std::string> Glob(const std::string& pattern) {
  glob_t found{};
  std::unique_ptr<glob_t, void (*)(glob_t*)> owner(&found, globfree);
  std::vector<std::string> files;
  if (glob(pattern.c_str(), GLOB_BRACE, nullptr, &found) != 0) return files;
  for (size_t i = 0; i < found.gl_pathc; ++i) {
    if (fs::is_regular_file(found.gl_pathv[i])) files.emplace_back(found.gl_pathv[i]);
  }
  return files;
}

std::vector<std::string> CsvFilesIn(const fs::path& folder) {
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    if (entry.is_regular_file() && ext == ".csv") files.push_back(entry.path().string());
  }
  return files;
}

// "007" -> "7" for an all-digit key; anything else unchanged.
std::string Canonical(const std::string& key) {
  if (key.empty() ||
      !std::all_of(key.begin(), key.end(), [](unsigned char c) { return std::isdigit(c); })) {
    return key;
  }
  const size_t first = key.find_first_not_of('0');
  return first == std::string::npos ? "0" : key.substr(first);
}

}  // namespace

std::vector<std::string> ResolveStreamFiles(const std::string& path, const std::string& flag) {
  std::vector<std::string> files;
  std::error_code ec;
  if (IsGlob(path) && !fs::exists(path, ec)) {
    files = Glob(path);
    if (files.empty()) throw MakeInputError(path, flag, "no file matches the pattern");
  } else if (fs::is_directory(path, ec)) {
    files = CsvFilesIn(path);
    if (files.empty()) throw MakeInputError(path, flag, "the folder holds no .csv file");
  } else {
    files = {path};  // read (and any error reported) by the CSV reader
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<std::string> TrialKeys(const std::vector<std::string>& names) {
  if (names.size() <= 1) return std::vector<std::string>(names.size());
  size_t prefix = names[0].size(), suffix = names[0].size();
  for (const std::string& n : names) {
    prefix = std::min(
        prefix,
        static_cast<size_t>(
            std::mismatch(n.begin(), n.end(), names[0].begin(), names[0].end()).first - n.begin()));
    suffix = std::min(
        suffix, static_cast<size_t>(
                    std::mismatch(n.rbegin(), n.rend(), names[0].rbegin(), names[0].rend()).first -
                    n.rbegin()));
  }
  // Never end the prefix or start the suffix inside a number or a word ("trial_1" of trial_1,
  // trial_10; "t/pose.csv" of left/pose.csv, right/pose.csv).
  auto kind = [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return std::isdigit(u) ? 1 : std::isalpha(u) ? 2 : 0;
  };
  const std::string& a = names[0];
  while (prefix > 0 && kind(a[prefix - 1]) != 0) {
    // Back off over the prefix's last token when some name continues it ("1" -> "10").
    bool continues = false;
    for (const std::string& n : names) {
      continues |= prefix < n.size() && kind(n[prefix]) == kind(a[prefix - 1]);
    }
    if (!continues) break;
    --prefix;
  }
  while (suffix > 0) {
    const size_t i = a.size() - suffix;  // first character of the suffix in a
    bool continues = false;
    for (const std::string& n : names) {
      const size_t j = n.size() - suffix;
      continues |= j > 0 && kind(n[j - 1]) != 0 && kind(n[j - 1]) == kind(a[i]);
    }
    if (!continues) break;
    --suffix;
  }
  std::vector<std::string> keys;
  for (const std::string& n : names) {
    const size_t length = n.size() >= prefix + suffix ? n.size() - prefix - suffix : 0;
    keys.push_back(Canonical(n.substr(std::min(prefix, n.size()), length)));
  }
  return keys;
}

std::vector<LogTrial> PairTrials(const std::vector<std::string>& commands,
                                 const std::vector<std::string>& pose,
                                 const std::vector<std::string>& attitude) {
  if (commands.size() == 1 && pose.size() == 1 && attitude.size() <= 1) {
    return {{"", commands[0], pose[0], attitude.empty() ? "" : attitude[0]}};
  }
  struct Stream {
    const char* flag;
    const std::vector<std::string>* files;
  };
  std::vector<Stream> streams = {{"--commands", &commands}, {"--pose", &pose}};
  if (!attitude.empty()) streams.push_back({"--attitude", &attitude});
  std::vector<std::map<std::string, std::string>> by_key(streams.size());
  for (size_t s = 0; s < streams.size(); ++s) {
    const std::vector<std::string> keys = TrialKeys(*streams[s].files);
    for (size_t i = 0; i < keys.size(); ++i) {
      const auto [it, fresh] = by_key[s].try_emplace(keys[i], (*streams[s].files)[i]);
      if (!fresh) {
        throw MakeInputError((*streams[s].files)[i], streams[s].flag,
                             "same trial name '" + keys[i] + "' as " + it->second +
                                 " (files are paired across streams by the part of their names "
                                 "that differs)");
      }
    }
  }
  // Every stream has a file for every trial of every other stream.
  for (size_t s = 0; s < streams.size(); ++s) {
    for (size_t o = 0; o < streams.size(); ++o) {
      for (const auto& [key, file] : by_key[s]) {
        if (by_key[o].count(key)) continue;
        throw MakeInputError(file, streams[o].flag,
                             "no " + std::string(streams[o].flag).substr(2) + " file for trial '" +
                                 key + "' (" + std::to_string(streams[o].files->size()) + " " +
                                 std::string(streams[o].flag).substr(2) + " files for " +
                                 std::to_string(streams[s].files->size()) + " " +
                                 std::string(streams[s].flag).substr(2) +
                                 " files; files are paired by the part of their names that "
                                 "differs)");
      }
    }
  }
  std::vector<LogTrial> trials;
  for (const auto& [key, file] : by_key[0]) {
    trials.push_back({key, file, by_key[1].at(key), attitude.empty() ? "" : by_key[2].at(key)});
  }
  // Trials in file order of the commands stream (numbers compare as numbers).
  std::sort(trials.begin(), trials.end(), [](const LogTrial& a, const LogTrial& b) {
    const bool na = !a.name.empty() && std::isdigit(static_cast<unsigned char>(a.name[0])) &&
                    a.name.size() < 19 &&
                    a.name.find_first_not_of("0123456789") == std::string::npos;
    const bool nb = !b.name.empty() && std::isdigit(static_cast<unsigned char>(b.name[0])) &&
                    b.name.size() < 19 &&
                    b.name.find_first_not_of("0123456789") == std::string::npos;
    if (na && nb) return std::stoll(a.name) < std::stoll(b.name);
    return a.commands < b.commands;
  });
  return trials;
}

}  // namespace dgmm
