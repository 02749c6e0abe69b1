#pragma once
// Refuses an output path that is one of the command's inputs (same file: same device and inode,
// whatever the spelling, hard links and symlinks included), before anything is read or written.
#include <string>
#include <vector>

namespace dgmm {

// Throws InputError "<output>: <flag>: is the same file as the input <input>; ..." when `output`
// exists and is the same file as one of `inputs` (missing inputs are skipped: their readers say
// so).
void RefuseOutputThatIsAnInput(const std::string& output, const std::vector<std::string>& inputs,
                               const std::string& flag = "-o");

// True when both paths exist and name the same file (device and inode).
bool SameFile(const std::string& a, const std::string& b);
// True when both are readable regular files with the same bytes (sizes compared first).
bool SameContent(const std::string& a, const std::string& b);

}  // namespace dgmm
