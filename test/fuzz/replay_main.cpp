// Replays files through a libFuzzer target's LLVMFuzzerTestOneInput without libFuzzer: the seed
// corpus and every input a fuzzer ever crashed on (test/fuzz/regressions/<target>/) become a
// normal test, run under AddressSanitizer + UndefinedBehaviorSanitizer by scripts/sanitizers.sh.
// Usage: fuzz_replay_<target> FILE_OR_DIRECTORY...   Exits non-zero if there is nothing to replay.
#include <dirent.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

void collect(const std::string& path, std::vector<std::string>& files) {
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0) return;
  if (!S_ISDIR(status.st_mode)) {
    files.push_back(path);
    return;
  }
  DIR* directory = ::opendir(path.c_str());
  if (directory == nullptr) return;
  std::vector<std::string> entries;
  while (const dirent* entry = ::readdir(directory)) {
    const std::string name = entry->d_name;
    if (name != "." && name != ".." && name != "README.md") entries.push_back(path + "/" + name);
  }
  ::closedir(directory);
  std::sort(entries.begin(), entries.end());
  for (const std::string& entry : entries) collect(entry, files);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> files;
  for (int k = 1; k < argc; ++k) collect(argv[k], files);
  for (const std::string& file : files) {
    std::ifstream in(file, std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)),
                                  std::istreambuf_iterator<char>());
    std::printf("replaying %s (%zu bytes)\n", file.c_str(), bytes.size());
    std::fflush(stdout);
    LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  }
  std::printf("%zu inputs replayed\n", files.size());
  return files.empty() ? 1 : 0;
}
