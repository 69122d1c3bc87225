// Atomic output: a file is written to a temporary name beside it and renamed into place, so a
// crash never leaves a half-written file that looks whole. The output folder's lock, manifest
// and consistent set of result files build on this (pipeline/store/output_set.h).
//
// What a writer never does (issue 23):
// - replace a file the user did not ask it to replace: a command that writes a path the user
//   named (init PATH, simulate --trace/--truth/--out, export --out) first calls
//   RefuseToReplace, which refuses an existing path unless --force was given;
// - replace or write through a symbolic link: the final component of the path must not be a
//   link (a link to /proc/self/fd/1, which is what /dev/stdout is, would otherwise be replaced
//   by a regular file, or the file behind it overwritten). Writing through was rejected: the
//   link's target is outside what the user named (any file, when run as root), and a
//   /proc/self/fd link resolves to a descriptor, a pipe or a deleted file, not a path. Give the
//   file's own path instead;
// - write a device, FIFO, socket or folder.
#pragma once

#include <string>

namespace bifilar {

// The temporary name WriteFileAtomically uses for `path`, in the same folder:
// "<path>.tmp.<pid>", or, when that name would be longer than the file system allows
// (NAME_MAX, 255 bytes), "<folder>/.bfl-<16 hex digits of the name's hash>.<pid>".
std::string AtomicTemporaryName(const std::string& path);

// Writes `text` to `path` atomically (temporary file in the same folder, created exclusively,
// then rename); creates missing parent folders. Throws UserError naming the path on failure,
// and before writing anything when `path` is a symbolic link (even one to a regular file), or
// exists and is not a regular file (a folder, device, FIFO or socket), or its file name is
// longer than the file system allows.
void WriteFileAtomically(const std::string& path, const std::string& text);

// The checks WriteFileAtomically makes before writing, for a command that checks every target
// before its first write: throws UserError naming `path` when it is a symbolic link (even one to
// a regular file, even dangling), exists and is not a regular file, or its file name is longer
// than the file system allows.
void CheckFileTarget(const std::string& path);

// The rule before writing a path the user named (the invariant "no command replaces a file it
// did not create without --force, and none replaces a link"): when `path` exists (a file, a link,
// even a dangling one, anything) and `force` is false, throws UserError
// "<what>: <path> exists; choose another name, or add --force to overwrite it"; with `force`, a
// link, folder, device, FIFO or socket is still refused (CheckFileTarget); an empty `path` is
// refused. `init` (its PATH), `simulate` (--trace, --truth, the files of --out), `export` (--out)
// and `plan --rig` (--write-config, --plot) use it, so every command says the same thing. A
// folder of figures written by name (`fit --plot DIR`, `ellipse --plot DIR`) follows the same
// rule through base/plot_folder.h; the output folder of `process` through its
// manifest (pipeline/store/output_set.h).
void RefuseToReplace(const std::string& path, const std::string& what, bool force);

}  // namespace bifilar
