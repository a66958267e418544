#include "core/output_dir.h"

#include <sys/stat.h>

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <stdexcept>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_file.h"
#include "core/run_program.h"

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
         name != kStagingRecord && name.find('/') == std::string::npos &&
         name.find('\0') == std::string::npos;
}

// --- SHA-256 (FIPS 180-4), the content proof of the manifests --------------------------------

class Sha256 {
 public:
  void Update(const char* data, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) {
      block_[fill_++] = static_cast<std::uint8_t>(data[i]);
      if (fill_ == 64) Compress();
    }
    bytes_ += n;
  }
  std::string HexDigest() {
    const std::uint64_t bits = bytes_ * 8;
    const char one = static_cast<char>(0x80), zero = 0;
    Update(&one, 1);
    while (fill_ != 56) Update(&zero, 1);
    for (int i = 7; i >= 0; --i) {
      const char b = static_cast<char>((bits >> (8 * i)) & 0xff);
      Update(&b, 1);
    }
    static const char* hex = "0123456789abcdef";
    std::string out;
    for (std::uint32_t w : h_)
      for (int i = 28; i >= 0; i -= 4) out += hex[(w >> i) & 0xf];
    return out;
  }

 private:
  static std::uint32_t Rot(std::uint32_t x, int n) { return (x >> n) | (x << (32 - n)); }
  void Compress() {
    static const std::uint32_t k[64] = {
        0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4,
        0xab1c5ed5, 0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe,
        0x9bdc06a7, 0xc19bf174, 0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f,
        0x4a7484aa, 0x5cb0a9dc, 0x76f988da, 0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7,
        0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967, 0x27b70a85, 0x2e1b2138, 0x4d2c6dfc,
        0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85, 0xa2bfe8a1, 0xa81a664b,
        0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070, 0x19a4c116,
        0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
        0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7,
        0xc67178f2};
    std::uint32_t w[64];
    for (int i = 0; i < 16; ++i)
      w[i] = (std::uint32_t{block_[4 * i]} << 24) | (std::uint32_t{block_[4 * i + 1]} << 16) |
             (std::uint32_t{block_[4 * i + 2]} << 8) | std::uint32_t{block_[4 * i + 3]};
    for (int i = 16; i < 64; ++i) {
      const std::uint32_t s0 = Rot(w[i - 15], 7) ^ Rot(w[i - 15], 18) ^ (w[i - 15] >> 3);
      const std::uint32_t s1 = Rot(w[i - 2], 17) ^ Rot(w[i - 2], 19) ^ (w[i - 2] >> 10);
      w[i] = w[i - 16] + s0 + w[i - 7] + s1;
    }
    std::uint32_t a = h_[0], b = h_[1], c = h_[2], d = h_[3], e = h_[4], f = h_[5], g = h_[6],
                  h = h_[7];
    for (int i = 0; i < 64; ++i) {
      const std::uint32_t t1 =
          h + (Rot(e, 6) ^ Rot(e, 11) ^ Rot(e, 25)) + ((e & f) ^ (~e & g)) + k[i] + w[i];
      const std::uint32_t t2 = (Rot(a, 2) ^ Rot(a, 13) ^ Rot(a, 22)) + ((a & b) ^ (a & c) ^ (b & c));
      h = g;
      g = f;
      f = e;
      e = d + t1;
      d = c;
      c = b;
      b = a;
      a = t1 + t2;
    }
    const std::uint32_t v[8] = {a, b, c, d, e, f, g, h};
    for (int i = 0; i < 8; ++i) h_[i] += v[i];
    fill_ = 0;
  }
  std::uint32_t h_[8] = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                         0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
  std::uint8_t block_[64] = {};
  std::size_t fill_ = 0;
  std::uint64_t bytes_ = 0;
};

std::string Sha256Hex(const std::string& text) {
  Sha256 h;
  h.Update(text.data(), text.size());
  return h.HexDigest();
}

// The SHA-256 of a regular file (not followed through a link); empty if it is not one or
// cannot be read.
std::string FileSha256(const fs::path& p) {
  struct stat st {};
  if (::lstat(p.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return "";
  const int fd = ::open(p.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return "";
  Sha256 h;
  char buffer[65536];
  ssize_t n = 0;
  while ((n = ::read(fd, buffer, sizeof buffer)) > 0 || (n < 0 && errno == EINTR))
    if (n > 0) h.Update(buffer, static_cast<std::size_t>(n));
  ::close(fd);
  return n < 0 ? "" : h.HexDigest();
}

// --- Manifests ---------------------------------------------------------------------------------

// What a manifest lists: files with the SHA-256 of the content whirl wrote (empty: an older
// manifest without hashes, which proves nothing) and sub-directories written through their own
// OutputDir.
struct Listing {
  std::map<std::string, std::string> files;  // name -> sha256
  std::set<std::string> dirs;
};

std::string KindName(const fs::file_status& s) {
  if (fs::is_symlink(s)) return "a symbolic link";
  if (fs::is_directory(s)) return "a directory";
  if (fs::is_regular_file(s)) return "a file";
  return "not a regular file";
}

// The manifest `file` (kOutputManifest, or kStagingRecord with schema `schema`); an InputError
// naming it when it is not one.
Listing ReadListing(const fs::path& file, const std::string& what,
                    const std::string& schema = "whirl.output_dir") {
  const nlohmann::json j = ReadJsonFile(file);
  const std::string rule = what + ": " + QuotedPath(file) +
                           " is not a whirl output manifest (schema " + schema +
                           " with a list of file names); remove the directory or choose another";
  if (!j.is_object() || !j.contains("schema") || j["schema"] != schema || !j.contains("files") ||
      !j["files"].is_array())
    throw InputError(rule);
  Listing out;
  for (const auto& f : j["files"]) {
    std::string name, hash;
    if (f.is_string()) {  // schema version 1: names only
      name = f.get<std::string>();
    } else if (f.is_object() && f.contains("name") && f["name"].is_string() &&
               f.contains("sha256") && f["sha256"].is_string()) {
      name = f["name"].get<std::string>();
      hash = f["sha256"].get<std::string>();
    } else {
      throw InputError(rule);
    }
    if (!ValidEntryName(name)) throw InputError(rule);
    out.files[name] = hash;
  }
  if (j.contains("directories")) {
    if (!j["directories"].is_array()) throw InputError(rule);
    for (const auto& d : j["directories"]) {
      if (!d.is_string() || !ValidEntryName(d.get<std::string>())) throw InputError(rule);
      out.dirs.insert(d.get<std::string>());
    }
  }
  return out;
}

std::string ListingText(const Listing& l, const std::string& schema, const std::string& note) {
  nlohmann::json files = nlohmann::json::array();
  for (const auto& [name, hash] : l.files) files.push_back({{"name", name}, {"sha256", hash}});
  nlohmann::json j = {{"schema", schema}, {"schema_version", 2}, {"note", note}, {"files", files}};
  if (!l.dirs.empty()) j["directories"] = std::vector<std::string>(l.dirs.begin(), l.dirs.end());
  return DumpJson(j) + "\n";
}

std::string ManifestText(const Listing& l) {
  return ListingText(
      l, "whirl.output_dir",
      "the files whirl wrote into this directory, with the SHA-256 of what it wrote: the next run "
      "replaces or removes only files whose content still matches; anything else in the directory "
      "(a file not listed here or changed since) makes whirl refuse the directory");
}

bool HasManifest(const fs::path& dir) {
  std::error_code ec;
  return fs::is_regular_file(fs::symlink_status(dir / kOutputManifest, ec));
}

bool ProcessRuns(long pid) {
  return pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH);
}

bool IsStagingName(const std::string& name) { return name.rfind(".whirl-stage-", 0) == 0; }

// --- The proof: what in a directory whirl can show it wrote -------------------------------------

// An output directory's entries that are provably whirl's.
struct Proof {
  Listing listing;                         // proven files (current hash) and directories
  std::vector<fs::path> stale_stagings;    // staging folders of runs that are gone, all proven
  std::string foreign, reason;             // the first entry that is not, and why ("" if none)
};

Proof ProveTree(const fs::path& dir, const std::string& what, const std::set<std::string>& kept);

// Why the staging folder `s` of a finished (killed) run holds something whirl did not put there;
// empty when every entry is recorded in its kStagingRecord with a matching hash (or is a whirl
// temporary) and it may be removed.
std::string UnprovenStaging(const fs::path& s, const std::string& what) {
  Listing record;
  const bool has_record = fs::is_regular_file(fs::symlink_status(s / kStagingRecord));
  if (has_record) {
    try {
      record = ReadListing(s / kStagingRecord, what, "whirl.output_dir.staging");
    } catch (const InputError&) {
      return std::string(kStagingRecord) + " is not whirl's record of the folder";
    }
  }
  std::error_code ec;
  for (fs::directory_iterator it(s, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string entry = it->path().filename().string();
    if (entry == kStagingRecord || IsWhirlTemporary(entry)) continue;
    const auto f = record.files.find(entry);
    if (f != record.files.end() && f->second == kProgramOutput &&
        fs::is_regular_file(it->symlink_status()))
      continue;  // named before whirl started the program that writes it
    if (f == record.files.end() || f->second.empty() || FileSha256(it->path()) != f->second)
      return QuotedPath(entry) + ", which whirl did not put there (or which changed since)";
  }
  if (ec) return "it cannot be listed (" + ec.message() + ")";
  return "";
}

// Why `entry` of `dir` is not provably whirl's ("" when it is; then it is recorded in `proof`).
std::string Unproven(const fs::path& dir, const std::string& entry, const Listing* listed,
                     const std::set<std::string>& kept, const std::string& what, Proof& proof) {
  static const Listing kNothing;
  const Listing& list = listed ? *listed : kNothing;
  const fs::path p = dir / entry;
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(p, ec);
  long pid = 0;
  if (entry == kOutputManifest) return "";
  if (IsWhirlTemporary(entry, &pid) && !IsStagingName(entry)) return "";  // a file's temporary
  if (IsStagingName(entry) && IsWhirlTemporary(entry, &pid) && fs::is_directory(st)) {
    if (ProcessRuns(pid)) return "";  // a running whirl's: not ours to judge
    const std::string why = UnprovenStaging(p, what);
    if (why.empty()) proof.stale_stagings.push_back(p);
    return why.empty() ? "" : "is named like whirl's staging folder but holds " + why;
  }
  const auto f = list.files.find(entry);
  if (f != list.files.end()) {
    if (!fs::is_regular_file(st)) return "is listed as a file whirl wrote but is " + KindName(st);
    if (f->second.empty())
      return "is listed without its content hash (a manifest of an older whirl), so whirl cannot "
             "prove it wrote it";
    const std::string now = FileSha256(p);
    if (now != f->second) return "changed since whirl wrote it (its content no longer matches)";
    proof.listing.files[entry] = now;
    return "";
  }
  if (fs::is_directory(st) && !fs::is_symlink(st) && HasManifest(p)) {
    const Proof inner = ProveTree(p, what, {});
    if (!inner.foreign.empty())
      return "is a directory whose " + QuotedPath(inner.foreign) + " " + inner.reason;
    // A whirl output directory of its own (the demo's report/): listed, kept by this run, or
    // left by a run killed before its parent's commit (tolerated, never removed unlisted).
    if (list.dirs.count(entry) > 0 || kept.count(entry) > 0) proof.listing.dirs.insert(entry);
    return "";
  }
  if (list.dirs.count(entry) > 0)
    return "is listed as whirl's directory but is " + KindName(st) + " without a whirl manifest";
  return listed ? "is not among the files whirl wrote there"
                : "whirl did not write (the directory has no " + std::string(kOutputManifest) +
                      ")";
}

Proof ProveTree(const fs::path& dir, const std::string& what, const std::set<std::string>& kept) {
  Proof proof;
  const bool manifest = HasManifest(dir);
  const Listing listed = manifest ? ReadListing(dir / kOutputManifest, what) : Listing{};
  std::vector<std::pair<std::string, std::string>> foreign;  // entry, reason
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string entry = it->path().filename().string();
    const std::string why = Unproven(dir, entry, manifest ? &listed : nullptr, kept, what, proof);
    if (!why.empty()) foreign.emplace_back(entry, why);
  }
  if (ec) throw InputError(what + " " + QuotedPath(dir) + ": cannot list it (" + ec.message() + ")");
  if (!foreign.empty()) {
    const auto first = *std::min_element(foreign.begin(), foreign.end());
    proof.foreign = first.first;
    proof.reason = first.second;
  }
  return proof;
}

// The rule of the header; returns what the directory provably holds of whirl's.
Proof Inspect(const fs::path& given, const std::string& what,
              const std::set<std::string>& kept = {}) {
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
  Proof proof = ProveTree(dir, what, kept);
  if (!proof.foreign.empty())
    throw InputError(name + " holds " + QuotedPath(proof.foreign) + ", which " + proof.reason +
                     "; whirl replaces and removes only files it can prove it wrote (listed in " +
                     std::string(kOutputManifest) +
                     " with the SHA-256 of their content) and writes only into a new or empty "
                     "directory or one it wrote before: choose another directory or move the "
                     "file away");
  return proof;
}

// Removes `p` if it is a regular file whose content still has the SHA-256 `hash`. Never throws.
void RemoveProvenFile(const fs::path& p, const std::string& hash) {
  std::error_code ec;
  if (!hash.empty() && FileSha256(p) == hash) fs::remove(p, ec);
}

// Removes the staging folder of a killed run: its recorded files whose content still matches,
// whirl temporaries, the record, then the folder if that left it empty. Never throws.
void RemoveStaleStaging(const fs::path& s) {
  Listing record;
  try {
    record = ReadListing(s / kStagingRecord, s.string(), "whirl.output_dir.staging");
  } catch (const InputError&) {
  }
  std::error_code ec;
  for (const auto& [name, hash] : record.files) {
    if (hash != kProgramOutput) {
      RemoveProvenFile(s / name, hash);
    } else if (fs::is_regular_file(fs::symlink_status(s / name, ec))) {
      fs::remove(s / name, ec);  // UnprovenStaging accepted it as the program's
    }
  }
  std::vector<fs::path> temporaries;
  for (fs::directory_iterator it(s, ec), end; !ec && it != end; it.increment(ec))
    if (IsWhirlTemporary(it->path().filename().string()) &&
        !fs::is_directory(it->symlink_status(ec)))
      temporaries.push_back(it->path());
  for (const auto& t : temporaries) fs::remove(t, ec);
  fs::remove(s / kStagingRecord, ec);
  fs::remove(s, ec);  // only if now empty
}

// Removes an output directory whirl wrote (a nested one, e.g. the demo's report/): every entry
// its manifest proves, then the manifest and the directory if that left it empty. Never throws;
// what is not provably whirl's stays.
void RemoveWhirlTree(const fs::path& dir) {
  Proof proof;
  try {
    proof = ProveTree(dir, dir.string(), {});
  } catch (const InputError&) {
    return;
  }
  for (const auto& [name, hash] : proof.listing.files) RemoveProvenFile(dir / name, hash);
  for (const auto& d : proof.listing.dirs) RemoveWhirlTree(dir / d);
  for (const auto& s : proof.stale_stagings) RemoveStaleStaging(s);
  RemoveStaleTemporaries(dir);
  std::error_code ec;
  if (proof.foreign.empty()) fs::remove(dir / kOutputManifest, ec);
  fs::remove(dir, ec);  // only if now empty
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
  if (!staging_.empty()) fs::remove_all(staging_, ec);  // this run's own folder
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

void OutputDir::WriteStagingRecord() const {
  Listing record;
  record.files = staged_;
  WriteFileAtomic(staging_ / kStagingRecord,
                  ListingText(record, "whirl.output_dir.staging",
                              "what whirl put into this staging folder, with SHA-256 (or " +
                                  std::string(kProgramOutput) +
                                  ": a file a program whirl ran was told to write); a later run "
                                  "removes only these files once this run is gone"));
}

void OutputDir::Stage(const std::string& name, const std::string& contents, bool write) {
  staged_[name] = Sha256Hex(contents);
  // The record first: a run killed between the two leaves a recorded name without its file
  // (harmless), never a file the next run cannot prove.
  WriteStagingRecord();
  if (write) WriteFileAtomic(staging_ / name, contents);
}

void OutputDir::Add(const std::string& name, std::string contents) {
  Insert(name, std::move(contents));
  if (!staging_.empty()) Stage(name, files_.back().second, true);
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
  for (const auto& [name, text] : files_) Stage(name, text, true);
  return staging_;
}

int OutputDir::RunInStaging(const std::vector<std::string>& argv, const std::string& log,
                            const std::vector<std::string>& outputs) {
  const fs::path stage = fs::absolute(Staging());
  for (const auto& name : outputs) {
    if (!ValidEntryName(name))
      throw InputError(what_ + ": " + QuotedPath(name) + " is not an entry name");
    if (!staged_.count(name)) staged_[name] = kProgramOutput;
  }
  if (!ValidEntryName(log)) throw InputError(what_ + ": " + QuotedPath(log) + " is not an entry name");
  if (!staged_.count(log)) staged_[log] = kProgramOutput;
  WriteStagingRecord();
  return RunProgram(argv, stage, stage / log);
}

void OutputDir::AddStaged(const std::string& name) {
  if (staging_.empty()) throw std::logic_error("OutputDir::AddStaged before Staging()");
  Insert(name, ReadTextFile(staging_ / name));
  Stage(name, files_.back().second, false);
}

bool OutputDir::AddProgramLog(const std::string& name) {
  std::error_code ec;
  if (staging_.empty() || !fs::is_regular_file(fs::symlink_status(staging_ / name, ec)))
    return false;
  AddStaged(name);
  return true;
}

void OutputDir::AddReady(const std::string& name, const fs::path& ready) {
  if (!ValidEntryName(name) || IsWhirlTemporary(name))
    throw InputError(what_ + " " + QuotedPath(dir_) + ": " + QuotedPath(name) +
                     " is not a file name whirl may write there");
  if (!names_.insert(name).second)
    throw InputError(what_ + " " + QuotedPath(dir_) + ": two outputs named " + QuotedPath(name));
  const std::string hash = FileSha256(ready);
  if (hash.empty())
    throw InputError(what_ + " " + QuotedPath(dir_) + ": cannot read back " + QuotedPath(ready));
  ready_.push_back({dir_ / name, ready});
  ready_hashes_[name] = hash;
}

std::vector<fs::path> OutputDir::Commit(const std::vector<std::pair<fs::path, std::string>>& also,
                                        const std::vector<ReadyFile>& also_ready) {
  // The rule again, just before writing; `before` is what the directory provably holds of whirl's.
  const Proof before = Inspect(dir_, what_, std::set<std::string>(kept_.begin(), kept_.end()));
  Create();
  for (const auto& s : before.stale_stagings) RemoveStaleStaging(s);
  RemoveStaleTemporaries(dir_);
  Listing now;
  now.dirs.insert(kept_.begin(), kept_.end());
  for (const auto& [name, text] : files_) now.files[name] = Sha256Hex(text);
  for (const auto& [name, hash] : ready_hashes_) now.files[name] = hash;
  Listing all = now;
  for (const auto& [name, hash] : before.listing.files)
    if (!now.files.count(name) && !now.dirs.count(name)) all.files[name] = hash;
  for (const auto& d : before.listing.dirs)
    if (!now.files.count(d)) all.dirs.insert(d);
  std::vector<std::pair<fs::path, std::string>> batch;
  std::vector<fs::path> written;
  for (auto& [name, text] : files_) {  // moved: a commit holds the files once (drift split)
    batch.emplace_back(dir_ / name, std::move(text));
    written.push_back(dir_ / name);
  }
  files_.clear();
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
  if (all.files.size() != now.files.size() || all.dirs.size() != now.dirs.size()) {
    for (const auto& [name, hash] : all.files)
      if (!now.files.count(name)) RemoveProvenFile(dir_ / name, hash);
    for (const auto& d : all.dirs)
      if (!now.dirs.count(d)) RemoveWhirlTree(dir_ / d);
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
