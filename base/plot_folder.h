// A folder a command writes its figures into by name (`fit --plot DIR`, `ellipse --plot DIR`):
// the rule of base/atomic_file.h for a folder (issue 33 item 1). bifilar replaces there only the
// files it wrote itself, which it records in DIR/.bifilar-plots.json (write-ahead, before the
// first figure is drawn, temporary names included, as the output folder of `process` records
// its own in pipeline/store/output_set.h); any other file of the same name is refused before
// anything is written, unless --force; a symbolic link, a folder, FIFO or device under a figure's
// name is refused even with --force (bifilar neither replaces a link nor writes through one).
#pragma once

#include <set>
#include <string>
#include <vector>

namespace bifilar {

class PlotFolder {
 public:
  static constexpr const char* kManifestName = ".bifilar-plots.json";

  // Creates `dir` (and its parents) when missing and reads its manifest. Throws UserError naming
  // `what` (the flag, "fit --plot") when the folder cannot be made or is not a folder, or its
  // manifest is damaged.
  PlotFolder(std::string dir, std::string what, bool force);

  // Before any of `names` (plain file names inside the folder) is written: throws UserError
  // naming every refused one (a file bifilar did not write there, without --force; a link or a
  // non-regular file, always); else records them and saves the manifest.
  void Claim(const std::vector<std::string>& names);

  // DIR/name.
  std::string PathOf(const std::string& name) const;

 private:
  void Save() const;
  std::string dir_, what_;
  bool force_ = false;
  std::set<std::string> files_;
};

}  // namespace bifilar
