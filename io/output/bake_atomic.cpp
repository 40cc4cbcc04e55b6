// Atomic replacement of output files (see bake_atomic.h).
#include "io/output/bake_atomic.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <mutex>

namespace gibake {
namespace {

// Temporaries and provisional outputs that a fatal signal must remove. Fixed storage: the handler
// may only use async-signal-safe calls (unlink, rmdir, sigaction, raise). Room for an export of
// many volumes' EXR files; pages never written cost no memory.
constexpr int kSlots = 1024;
char g_paths[kSlots][PATH_MAX];
volatile sig_atomic_t g_used[kSlots];  // 0 free, 1 a file to remove, 2 a folder to remove if empty
const int kSignals[] = {SIGINT, SIGTERM, SIGHUP};
struct sigaction g_previous[3];
std::mutex g_mutex;

extern "C" void cleanup_handler(int sig) {
  for (int i = 0; i < kSlots; ++i)
    if (g_used[i] == 1) unlink(g_paths[i]);
  for (int i = 0; i < kSlots; ++i)  // after the files: a folder goes only once empty
    if (g_used[i] == 2) rmdir(g_paths[i]);
  for (int i = 0; i < 3; ++i)
    if (kSignals[i] == sig) sigaction(sig, &g_previous[i], nullptr);
  raise(sig);  // delivered to the previous disposition once this handler returns
}

// Blocks the cleanup signals for the lifetime of the guard.
struct SignalBlock {
  sigset_t old;
  SignalBlock() {
    sigset_t set;
    sigemptyset(&set);
    for (int s : kSignals) sigaddset(&set, s);
    pthread_sigmask(SIG_BLOCK, &set, &old);
  }
  ~SignalBlock() { pthread_sigmask(SIG_SETMASK, &old, nullptr); }
};

int register_path(const std::string& path, int kind) {
  if (path.size() >= PATH_MAX) return -1;
  std::lock_guard<std::mutex> lock(g_mutex);
  SignalBlock block;
  for (int i = 0; i < 3; ++i) {
    struct sigaction current;
    sigaction(kSignals[i], nullptr, &current);
    // Already ours, or ignored (e.g. SIGHUP under nohup): a signal that does not end the
    // process must not remove the temporary it is still writing.
    if (current.sa_handler == cleanup_handler || current.sa_handler == SIG_IGN) continue;
    struct sigaction action {};
    action.sa_handler = cleanup_handler;
    sigemptyset(&action.sa_mask);
    sigaction(kSignals[i], &action, &g_previous[i]);
  }
  for (int i = 0; i < kSlots; ++i) {
    if (g_used[i]) continue;
    std::memcpy(g_paths[i], path.c_str(), path.size() + 1);
    g_used[i] = kind;
    return i;
  }
  return -1;
}

int register_temp(const std::string& path) { return register_path(path, 1); }

void unregister_temp(int slot) {
  if (slot < 0) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  SignalBlock block;
  g_used[slot] = 0;
}

std::string folder_of(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

std::string errno_text(const std::string& what) { return what + ": " + std::strerror(errno); }

// A SIGKILLed writer cannot remove its temporary. Temporaries are named ".<name>.tmp.<pid>.XXXXXX",
// so the next write to the same target removes those whose process no longer exists.
void remove_stale_temps(const std::string& folder, const std::string& name) {
  const std::string prefix = "." + name + ".tmp.";
  DIR* dir = opendir(folder.c_str());
  if (!dir) return;
  while (const dirent* entry = readdir(dir)) {
    const std::string file = entry->d_name;
    if (file.compare(0, prefix.size(), prefix) != 0) continue;
    char* end = nullptr;
    const long pid = std::strtol(file.c_str() + prefix.size(), &end, 10);
    if (pid <= 0 || end == nullptr || *end != '.') continue;
    if (kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;  // still running
    unlinkat(dirfd(dir), file.c_str(), 0);
  }
  closedir(dir);
}

}  // namespace

ProvisionalOutputs::~ProvisionalOutputs() { keep(); }

void ProvisionalOutputs::add_file(const std::string& path) { slots_.push_back(register_path(path, 1)); }

void ProvisionalOutputs::add_folder(const std::string& path) { slots_.push_back(register_path(path, 2)); }

void ProvisionalOutputs::keep() {
  for (int slot : slots_) unregister_temp(slot);
  slots_.clear();
}

bool same_file(const std::string& a, const std::string& b) {
  struct stat sa, sb;
  if (stat(a.c_str(), &sa) != 0 || stat(b.c_str(), &sb) != 0) return false;
  return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

AtomicFile::~AtomicFile() { abandon(); }

void AtomicFile::abandon() {
  if (fd_ >= 0) close(fd_);
  fd_ = -1;
  if (!temp_.empty()) unlink(temp_.c_str());
  unregister_temp(slot_);
  slot_ = -1;
  temp_.clear();
}

Status AtomicFile::begin(const std::string& path, const std::vector<std::string>& inputs) {
  abandon();
  path_ = path;
  const std::string folder = folder_of(path);
  struct stat st;
  if (stat(folder.c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
    return Status::io(path, "folder does not exist: " + folder);
  const bool exists = stat(path.c_str(), &st) == 0;
  if (exists && S_ISDIR(st.st_mode)) return Status::io(path, "is a folder, not a file");
  for (const std::string& input : inputs)
    if (exists && same_file(path, input))
      return Status::error(ExitCode::BadArguments, path, "",
                           "refusing to overwrite an input of this bake (" + input + ")");
  const size_t slash = path.find_last_of('/');
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  remove_stale_temps(folder, name);
  std::string pattern = (slash == std::string::npos ? std::string() : path.substr(0, slash + 1)) + "." +
                        name + ".tmp." + std::to_string(getpid()) + ".XXXXXX";
  std::vector<char> buffer(pattern.begin(), pattern.end());
  buffer.push_back('\0');
  {
    SignalBlock block;  // no signal between creating the temporary and registering it
    fd_ = mkstemp(buffer.data());
    if (fd_ < 0) return Status::io(path, errno_text("cannot create temporary file in " + folder));
    temp_ = buffer.data();
    slot_ = register_temp(temp_);
  }
  mode_t mode = 0666;
  if (exists) {
    mode = st.st_mode & 07777;
  } else {
    const mode_t mask = umask(0);
    umask(mask);
    mode &= ~mask;
  }
  fchmod(fd_, mode);
  return Status::ok();
}

Status AtomicFile::write(const void* data, size_t size) {
  if (fd_ < 0) return Status::io(path_, "temporary file is not open");
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd_, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const Status s = Status::io(path_, errno_text("write failed"));
      abandon();
      return s;
    }
    p += n;
    size -= size_t(n);
  }
  return Status::ok();
}

Status AtomicFile::write_at(uint64_t offset, const void* data, size_t size) {
  if (fd_ < 0) return Status::io(path_, "temporary file is not open");
  const char* p = static_cast<const char*>(data);
  const uint64_t first = offset;
  const size_t total = size;
  while (size > 0) {
    const ssize_t n = ::pwrite(fd_, p, size, off_t(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return Status::io(path_, errno_text("write failed"));
    p += n;
    offset += uint64_t(n);
    size -= size_t(n);
  }
#ifdef SYNC_FILE_RANGE_WRITE
  if (total > 0) sync_file_range(fd_, off_t(first), off_t(total), SYNC_FILE_RANGE_WRITE);  // a hint: errors come at fsync
#else
  (void)first;
  (void)total;
#endif
  return Status::ok();
}

Status AtomicFile::commit(bool durable) {
  if (temp_.empty()) return Status::io(path_, "no temporary file to commit");
  // A library may have rewritten the temporary by name: reopen it for the fsync.
  if (fd_ >= 0) close(fd_);
  fd_ = durable ? open(temp_.c_str(), O_RDONLY) : -1;
  if (durable && (fd_ < 0 || fsync(fd_) != 0)) {
    const Status s = Status::io(path_, errno_text("fsync failed"));
    abandon();
    return s;
  }
  if (fd_ >= 0) close(fd_);
  fd_ = -1;
  // The last guard for every command, whatever it checked before: a rename would replace a device
  // node or FIFO (/dev/null, as root) with a regular file.
  struct stat target;
  if (lstat(path_.c_str(), &target) == 0 && !S_ISREG(target.st_mode) && !S_ISLNK(target.st_mode)) {
    abandon();
    return Status::io(path_, "is a device, FIFO, socket or folder, not a file: outputs replace their file whole");
  }
  {
    SignalBlock block;
    if (rename(temp_.c_str(), path_.c_str()) != 0) {
      const Status s = Status::io(path_, errno_text("rename failed"));
      abandon();
      return s;
    }
    temp_.clear();
    unregister_temp(slot_);
    slot_ = -1;
  }
  if (!durable) return Status::ok();
  const int dir = open(folder_of(path_).c_str(), O_RDONLY | O_DIRECTORY);
  if (dir >= 0) {
    fsync(dir);
    close(dir);
  }
  return Status::ok();
}

Status write_file_atomic(const std::string& path, const void* data, size_t size,
                         const std::vector<std::string>& inputs) {
  AtomicFile file;
  GIBAKE_TRY(file.begin(path, inputs));
  GIBAKE_TRY(file.write(data, size));
  return file.commit();
}

}  // namespace gibake
