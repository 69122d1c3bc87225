// The output folder of `bifilar process` (OUT) as a unit that is never shared, never holds a
// mixed set, and from which bifilar removes only what it wrote itself.
//
// - Lock: OUT/.bifilar.lock is held with flock(2) for the whole run (and by `bifilar report`).
//   A second run on the same OUT fails at once, naming the holder's pid and start time. It is
//   opened without following a link and never truncated; anything but a regular file of its
//   own (a link, a hard link to another file, a FIFO, a file holding other data) is refused.
// - Manifest: OUT/.bifilar-manifest.json lists every file bifilar wrote in the places it owns
//   (OUT/cache/, OUT/figures/ and the four result files). Names are recorded before the files
//   are created (write-ahead, temporary names included), so a run killed at any point leaves
//   nothing unrecorded. Clean-up removes only recorded files; a file in an owned place that is
//   not recorded (the user's) makes the run refuse the folder before any work. A folder written
//   before the manifest existed is adopted through its results.json: the files it names.
//   Nothing outside OUT is ever removed (issue 15): a manifest entry that is not a name bifilar
//   writes there, or that resolves to anything but a regular file inside OUT (a symbolic link,
//   cache/ or figures/ being a link), makes the manifest damaged and the run stop; removal opens
//   the folders below OUT without following links.
// - Consistent set: results.json is written last and carries the FNV-1a 64 hashes of
//   traces.csv and angles.csv; report.html carries the hash of the results.json it was built
//   from. CheckOutputSet finds a mixed set (a run killed between two renames).
#pragma once

#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace bifilar {

// Holds OUT/.bifilar.lock (created) until destroyed. Throws UserError when another process
// holds it ("OUT is in use by bifilar pid N, started T"), the folder cannot be written, or the
// lock is not a regular file of bifilar's own (a symbolic link, even dangling; a hard link; a
// FIFO, device or folder; a file holding anything but a holder line), named.
class OutputFolderLock {
 public:
  explicit OutputFolderLock(const std::string& out_dir);
  ~OutputFolderLock();
  OutputFolderLock(const OutputFolderLock&) = delete;
  OutputFolderLock& operator=(const OutputFolderLock&) = delete;

 private:
  int fd_ = -1;
};

// The record of what bifilar wrote in OUT. Paths are relative to OUT ("cache/<key>.json").
class OutputManifest {
 public:
  static constexpr const char* kFileName = ".bifilar-manifest.json";
  // Reads OUT/.bifilar-manifest.json when present. Throws UserError when it is damaged: not
  // JSON, or an entry that is not a name bifilar writes in OUT (a result file, cache/<n>.json,
  // figures/<n>, or their temporary names: no "..", no absolute path), or one that is there but
  // is not a regular file, or lies behind a symbolic link (each refused entry named).
  explicit OutputManifest(std::string out_dir);

  // Throws UserError naming the first foreign entries when OUT/cache/ or OUT/figures/ hold
  // anything not recorded, or a result file (results.json, traces.csv, angles.csv,
  // report.html) exists that bifilar did not write.
  void CheckOwnedPlaces() const;

  // Records `relative` paths (and their temporary names) before they are written; saves.
  void Record(const std::vector<std::string>& relative);
  bool Contains(const std::string& relative) const { return files_.count(relative) > 0; }

  // Removes every recorded file not in `keep` (relative paths), forgets recorded files that no
  // longer exist, and saves. Never touches an unrecorded file, and removes only regular files
  // reached without a symbolic link below OUT; returns one warning per recorded entry refused
  // for that (left alone and forgotten).
  std::vector<std::string> Prune(const std::set<std::string>& keep);

 private:
  void Save() const;
  void AdoptLegacy();
  std::string out_dir_;
  std::set<std::string> files_;
};

// FNV-1a 64 of a file's bytes as 16 hex digits ("" when it cannot be read).
std::string FileHash(const std::string& path);

// Writes traces.csv, angles.csv, report.html (when `report_html_builder` is set; else an old
// report.html is removed) and, last, results.json with "outputs": {name: hash} of its siblings.
// The report is built from the final document and stamped with the hash of its text.
// Each file is written atomically.
void WriteOutputSet(const std::string& out_dir, nlohmann::json results,
                    const std::string& traces_csv, const std::string& angles_csv,
                    std::string (*report_html_builder)(const nlohmann::json&, const std::string&));

// The report page stamped with the hash of the results.json text it shows.
std::string StampReport(const std::string& html, const std::string& results_hash);

// Problems of the set in OUT: a sibling that does not match the hash in results.json, a figure
// named in results.json that is missing, and (with `check_report`) a report built from another
// results.json. Empty when consistent (or when results.json predates the hashes).
std::vector<std::string> CheckOutputSet(const std::string& out_dir, bool check_report);

// A file name read from results.json (a figure, under OUT/figures; an output, under OUT) as the
// path to read: true with *path = folder/sub/name when `name` is a plain relative name (not
// empty, no NUL, not absolute, no '..' component) whose file (or where it would be), once every
// symbolic link is followed, lies inside `folder`; else false with *why ("an absolute path", "a
// '..' component", "a link leading out of OUT"). A results.json from someone else can then
// neither read nor change a file outside its folder (issue 33 item 2).
bool ResolveInsideFolder(const std::string& folder, const std::string& sub, const std::string& name,
                         std::string* path, std::string* why);

// Throws UserError naming the first of the result files, the manifest and the entries of cache/
// and figures/ that exists and is not a regular file (a FIFO, device, socket or folder, also
// behind a symlink): bifilar reads and writes only regular files there, and a FIFO would block
// a reader. Called before any fit, so such a folder stops the run at once.
void RefuseNonRegularOutputs(const std::string& out_dir);

}  // namespace bifilar
