// A file several processes update at once (a coverage file merged into by every process of a
// run): read, transformed and replaced whole under an exclusive lock, so that none of the
// updates is lost and a reader never sees half a file. Plain files only; no format here.
#pragma once

#include <functional>
#include <string>

namespace l6470emu {

/// Turns a file's current text ("" when it is missing or empty) into its new text; on failure
/// sets `error` to one line (the file is then left as it is).
using FileTransform = std::function<std::string(const std::string& old_text, std::string& error)>;

/// Locks the file at `path` (created when missing, mode 0644; a symbolic link: the file it names),
/// reads it, writes `transform`'s text beside it and renames it over the file: processes updating it at once take turns, each
/// seeing the others' updates. Returns "" or one line saying why not.
std::string update_file_locked(const std::string& path, const FileTransform& transform);

/// Whether a file at `path` could be created or rewritten now: "" or one line saying why not
/// (a directory, not a regular file, no write permission on it or on its folder).
std::string file_writable(const std::string& path);

}  // namespace l6470emu
