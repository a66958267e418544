#include "core/output_dir.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_file.h"

namespace whirl {
namespace {
namespace fs = std::filesystem;

std::string QuotedPath(const fs::path& p) { return "'" + p.string() + "'"; }

// "out/", "out/." and "out" are the same directory; lstat of "link/" would follow the link.
fs::path WithoutTrailingSeparator(const fs::path& p) {
  fs::path n = p.lexically_normal();
  while (!n.has_filename() && n.has_parent_path() && n.parent_path() != n) n = n.parent_path();
  return n;
}

bool ValidEntryName(const std::string& name) {
  return !name.empty() && name != "." && name != ".." && name != kOutputManifest &&
         name.find('/') == std::string::npos && name.find('\0') == std::string::npos;
}

// The names a manifest lists; an InputError naming it when it is not whirl's manifest.
std::set<std::string> ReadManifest(const fs::path& file, const std::string& what) {
  const nlohmann::json j = ReadJsonFile(file);
  const std::string rule = what + ": " + QuotedPath(file) +
                           " is not a whirl output manifest (schema whirl.output_dir with a list "
                           "of file names); remove the directory or choose another";
  if (!j.is_object() || j.value("schema", "") != "whirl.output_dir" || !j.contains("files") ||
      !j["files"].is_array())
    throw InputError(rule);
  std::set<std::string> names;
  for (const auto& f : j["files"]) {
    if (!f.is_string() || !ValidEntryName(f.get<std::string>())) throw InputError(rule);
    names.insert(f.get<std::string>());
  }
  return names;
}

std::string ManifestText(const std::set<std::string>& names) {
  const nlohmann::json j = {
      {"schema", "whirl.output_dir"},
      {"schema_version", 1},
      {"note",
       "the files whirl wrote into this directory: the next run replaces them and removes those it "
       "does not write again; whirl refuses the directory if it holds anything else"},
      {"files", std::vector<std::string>(names.begin(), names.end())}};
  return j.dump(2) + "\n";
}

bool HasManifest(const fs::path& dir) {
  std::error_code ec;
  return fs::is_regular_file(fs::symlink_status(dir / kOutputManifest, ec));
}

// The rule of the header; returns the names the manifest lists (the previous run's files).
std::set<std::string> Inspect(const fs::path& given, const std::string& what) {
  const fs::path dir = WithoutTrailingSeparator(given);
  const std::string name = what + " " + QuotedPath(given);
  if (dir.empty()) throw InputError(what + ": empty directory path");
  struct stat st {};
  if (::lstat(dir.c_str(), &st) != 0) {
    if (errno == ENOENT) return {};
    throw InputError(name + ": " + std::strerror(errno));
  }
  if (S_ISLNK(st.st_mode))
    throw InputError(name +
                     " is a symbolic link: whirl writes only into a real directory (a link could "
                     "send the files elsewhere); give the directory it points to, or a new path");
  if (!S_ISDIR(st.st_mode))
    throw InputError(name + " exists and is not a directory; give a new or an empty directory");
  const bool manifest = HasManifest(dir);
  const std::set<std::string> listed =
      manifest ? ReadManifest(dir / kOutputManifest, what) : std::set<std::string>{};
  std::vector<std::string> foreign;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string entry = it->path().filename().string();
    if (entry == kOutputManifest || IsWhirlTemporary(entry) || listed.count(entry) > 0) continue;
    std::error_code e2;
    if (fs::is_directory(it->symlink_status(e2)) && HasManifest(it->path())) continue;
    foreign.push_back(entry);
  }
  if (ec) throw InputError(name + ": cannot list it (" + ec.message() + ")");
  if (!foreign.empty())
    throw InputError(name + " holds " +
                     QuotedPath(*std::min_element(foreign.begin(), foreign.end())) +
                     (manifest ? ", which is not among the files whirl wrote there ("
                               : ", and whirl did not write into it (no ") +
                     std::string(kOutputManifest) +
                     "); whirl writes only into a new or empty directory or one it wrote before: "
                     "choose another directory or move the file away");
  return listed;
}

// Removes an entry the previous run wrote: a file (or a link itself), or a nested output
// directory through its own manifest. Never throws; what cannot be removed stays.
void RemoveWhirlEntry(const fs::path& p) {
  std::error_code ec;
  const fs::file_status s = fs::symlink_status(p, ec);
  if (ec || !fs::exists(s)) return;
  if (!fs::is_directory(s)) {
    fs::remove(p, ec);
    return;
  }
  if (!HasManifest(p)) return;  // not whirl's: left alone
  try {
    for (const auto& name : ReadManifest(p / kOutputManifest, p.string()))
      RemoveWhirlEntry(p / name);
  } catch (const InputError&) {
    return;
  }
  RemoveStaleTemporaries(p);
  fs::remove(p / kOutputManifest, ec);
  fs::remove(p, ec);  // only if now empty
}

// Canonical absolute form for comparisons: through links, "." and ".."; a path that does not
// exist yet by its existing parent.
fs::path Resolved(const fs::path& p) {
  std::error_code ec;
  const fs::path abs = fs::absolute(p, ec);
  const fs::path c = fs::weakly_canonical(abs, ec);
  return WithoutTrailingSeparator(ec ? abs : c);
}

bool SameFile(const fs::path& a, const fs::path& b) {
  if (Resolved(a) == Resolved(b)) return true;
  struct stat sa {
  }, sb{};
  return ::stat(a.c_str(), &sa) == 0 && ::stat(b.c_str(), &sb) == 0 && sa.st_dev == sb.st_dev &&
         sa.st_ino == sb.st_ino;
}

// `p` is `dir` or lies below it.
bool Inside(const fs::path& p, const fs::path& dir) {
  const fs::path rp = Resolved(p), rd = Resolved(dir);
  auto a = rp.begin(), b = rd.begin();
  for (; b != rd.end(); ++a, ++b)
    if (a == rp.end() || *a != *b) return false;
  return true;
}

std::string Named(const FlagPath& f) { return f.flag + " " + QuotedPath(f.path); }

}  // namespace

void CheckOutputDir(const fs::path& dir, const std::string& what) { Inspect(dir, what); }

OutputDir::OutputDir(fs::path dir, std::string what)
    : dir_(std::move(dir)), what_(std::move(what)) {
  Inspect(dir_, what_);
}

OutputDir::~OutputDir() {
  std::error_code ec;
  if (!staging_.empty()) fs::remove_all(staging_, ec);
  if (created_ && !committed_) fs::remove(dir_, ec);  // only if empty: nothing of this run
}

const fs::path& OutputDir::Create() {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(dir_, ec))) {
    fs::create_directories(dir_, ec);
    if (ec)
      throw InputError(what_ + " " + QuotedPath(dir_) + ": cannot create it (" + ec.message() +
                       ")");
    created_ = true;
  }
  return dir_;
}

void OutputDir::Insert(const std::string& name, std::string contents) {
  if (!ValidEntryName(name) || IsWhirlTemporary(name))
    throw InputError(what_ + " " + QuotedPath(dir_) + ": " + QuotedPath(name) +
                     " is not a file name whirl may write there");
  if (!names_.insert(name).second)
    throw InputError(what_ + " " + QuotedPath(dir_) + ": two outputs named " + QuotedPath(name));
  files_.emplace_back(name, std::move(contents));
}

void OutputDir::Add(const std::string& name, std::string contents) {
  Insert(name, std::move(contents));
  if (!staging_.empty()) WriteFileAtomic(staging_ / name, files_.back().second);
}

void OutputDir::Keep(const std::string& name) {
  if (!ValidEntryName(name))
    throw InputError(what_ + ": " + QuotedPath(name) + " is not an entry name");
  kept_.push_back(name);
}

const fs::path& OutputDir::Staging() {
  if (!staging_.empty()) return staging_;
  Create();
  const fs::path s = dir_ / WhirlTemporaryName("", "");
  std::error_code ec;
  if (!fs::create_directory(s, ec))
    throw InputError(what_ + " " + QuotedPath(dir_) + ": cannot create a staging folder (" +
                     ec.message() + ")");
  staging_ = s;
  for (const auto& [name, text] : files_) WriteFileAtomic(staging_ / name, text);
  return staging_;
}

void OutputDir::AddStaged(const std::string& name) {
  if (staging_.empty()) throw std::logic_error("OutputDir::AddStaged before Staging()");
  Insert(name, ReadTextFile(staging_ / name));
}

void OutputDir::AddReady(const std::string& name, const fs::path& ready) {
  if (!ValidEntryName(name) || IsWhirlTemporary(name))
    throw InputError(what_ + " " + QuotedPath(dir_) + ": " + QuotedPath(name) +
                     " is not a file name whirl may write there");
  if (!names_.insert(name).second)
    throw InputError(what_ + " " + QuotedPath(dir_) + ": two outputs named " + QuotedPath(name));
  ready_.push_back({dir_ / name, ready});
}

std::vector<fs::path> OutputDir::Commit(const std::vector<std::pair<fs::path, std::string>>& also,
                                        const std::vector<ReadyFile>& also_ready) {
  const std::set<std::string> before = Inspect(dir_, what_);  // the rule again, just before writing
  Create();
  RemoveStaleTemporaries(dir_);
  std::set<std::string> now(kept_.begin(), kept_.end());
  for (const auto& f : files_) now.insert(f.first);
  for (const auto& r : ready_) now.insert(r.path.filename().string());
  std::set<std::string> all = now;
  all.insert(before.begin(), before.end());
  std::vector<std::pair<fs::path, std::string>> batch;
  std::vector<fs::path> written;
  for (const auto& [name, text] : files_) {
    batch.emplace_back(dir_ / name, text);
    written.push_back(dir_ / name);
  }
  batch.insert(batch.end(), also.begin(), also.end());
  // Until the old files are gone the manifest lists them too, so a run killed in between
  // leaves a directory the next run accepts.
  batch.emplace_back(dir_ / kOutputManifest, ManifestText(all));
  std::vector<ReadyFile> ready = ready_;
  for (const auto& r : ready_) written.push_back(r.path);
  ready.insert(ready.end(), also_ready.begin(), also_ready.end());
  WriteFilesAtomic(batch, ready);
  committed_ = true;
  std::error_code ec;
  if (!staging_.empty()) fs::remove_all(staging_, ec);
  staging_.clear();
  if (all.size() != now.size()) {
    for (const auto& name : before)
      if (now.count(name) == 0) RemoveWhirlEntry(dir_ / name);
    WriteFileAtomic(dir_ / kOutputManifest, ManifestText(now));
  }
  return written;
}

void CheckOutputs(const std::vector<FlagPath>& inputs, const std::vector<FlagPath>& files,
                  const std::vector<FlagPath>& dirs) {
  const auto given = [](const std::vector<FlagPath>& v) {
    std::vector<FlagPath> out;
    for (const auto& f : v)
      if (!f.path.empty()) out.push_back(f);
    return out;
  };
  const std::vector<FlagPath> in = given(inputs), out = given(files), dir = given(dirs);
  const std::string never =
      ": whirl never writes over its own inputs or outputs; choose another path";
  for (const auto& o : out)
    for (const auto& i : in)
      if (SameFile(o.path, i.path))
        throw InputError(Named(o) + " is the input " + Named(i) + " (both are " +
                         QuotedPath(Resolved(i.path)) + ")" + never);
  for (std::size_t a = 0; a < out.size(); ++a)
    for (std::size_t b = a + 1; b < out.size(); ++b)
      if (SameFile(out[a].path, out[b].path))
        throw InputError(Named(out[a]) + " and " + Named(out[b]) + " are the same file (" +
                         QuotedPath(Resolved(out[a].path)) + ")" + never);
  for (std::size_t a = 0; a < dir.size(); ++a) {
    for (const auto& i : in)
      if (Inside(i.path, dir[a].path))
        throw InputError(Named(dir[a]) + " holds the input " + Named(i) +
                         " (whirl replaces and removes the files of its output directories)" +
                         never);
    for (const auto& o : out)
      if (Inside(o.path, dir[a].path))
        throw InputError(Named(o) + " lies inside the output directory " + Named(dir[a]) + never);
    for (std::size_t b = 0; b < dir.size(); ++b)
      if (a != b && Inside(dir[b].path, dir[a].path))
        throw InputError(Named(dir[b]) + " lies inside the output directory " + Named(dir[a]) +
                         never);
  }
  for (const auto& o : out) {
    try {
      CheckOutputFile(o.path);
    } catch (const InputError& e) {
      throw InputError(o.flag + ": " + e.what());
    }
  }
  for (const auto& d : dir) CheckOutputDir(d.path, d.flag);
}

}  // namespace whirl
