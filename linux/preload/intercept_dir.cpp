// Replaced directory listing: opendir/readdir/closedir and scandir of /dev (and the sysfs
// directories of the emulated view) also list the emulated nodes, so gpiodetect, gpiofind
// and globbing for /dev/spidev* find them. A directory only the emulated view has
// (/sys/class/pwm/pwmchip0 on a machine without PWM) lists its entries alone: its DIR is a
// stand-in on "/" whose real entries are hidden (dirfd() of it is "/"). Other directories are
// untouched.
#include <dirent.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <mutex>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "linux/preload/real.hpp"
#include "linux/preload/state.hpp"
#include "linux/preload/sysfs.hpp"

using namespace l6470emu;
using namespace l6470emu::preload;

namespace {

struct Listing {
  std::vector<std::pair<std::string, unsigned char>> extra;
  std::set<std::string> seen;
  bool hide_real = false;  // a stand-in for a directory only the emulated view has
  std::size_t next = 0;
  dirent current{};
};

std::mutex g_mutex;
std::unordered_map<DIR*, Listing>* g_listings = nullptr;

std::vector<std::pair<std::string, unsigned char>> extras_for(const char* path) {
  if (!path || inside() || !active() || (strncmp(path, "/dev", 4) != 0 && strncmp(path, "/sys/", 5) != 0)) return {};
  Guard guard;
  try {
    return virtual_dir_entries(path);
  } catch (...) {
    return {};
  }
}

// Whether `path` is a directory only the emulated view has.
bool virtual_only_dir(const char* path) {
  if (!path || inside() || !active() || strncmp(path, "/sys/", 5) != 0) return false;
  Guard guard;
  try {
    return lookup_virtual(path, true).type == VirtualPath::Type::directory && real::access(path, F_OK) != 0;
  } catch (...) {
    return false;
  }
}

void fill_dirent(dirent& d, const std::string& name, unsigned char type, std::size_t i) {
  memset(&d, 0, sizeof d);
  d.d_ino = 0x64700000u + i;
  d.d_type = type;
  d.d_reclen = sizeof d;
  strncpy(d.d_name, name.c_str(), sizeof d.d_name - 1);
}

dirent* readdir_impl(DIR* dir) {
  Listing* l = nullptr;
  if (g_listings) {
    std::lock_guard lock(g_mutex);
    auto it = g_listings->find(dir);
    if (it != g_listings->end()) l = &it->second;
  }
  const int saved = errno;
  dirent* d = l && l->hide_real ? nullptr : real::readdir(dir);
  if (!l) return d;
  if (d) {
    l->seen.insert(d->d_name);
    return d;
  }
  if (errno != saved) return nullptr;  // a real error
  while (l->next < l->extra.size()) {
    const auto& [name, type] = l->extra[l->next++];
    if (l->seen.count(name)) continue;
    fill_dirent(l->current, name, type, l->next);
    return &l->current;
  }
  return nullptr;
}

int scandir_impl(const char* path, dirent*** out, int (*filter)(const dirent*),
                 int (*compar)(const dirent**, const dirent**)) {
  auto extra = extras_for(path);
  if (extra.empty()) return real::scandir(path, out, filter, compar);
  dirent** list = nullptr;
  const int n = virtual_only_dir(path) ? 0 : real::scandir(path, &list, nullptr, nullptr);
  if (n < 0) return n;
  std::vector<dirent*> kept;
  std::set<std::string> names;
  for (int i = 0; i < n; ++i) {
    names.insert(list[i]->d_name);
    if (!filter || filter(list[i]))
      kept.push_back(list[i]);
    else
      free(list[i]);
  }
  free(list);
  std::size_t idx = 0;
  for (const auto& [name, type] : extra) {
    ++idx;
    if (names.count(name)) continue;
    auto* d = static_cast<dirent*>(malloc(sizeof(dirent)));
    if (!d) continue;
    fill_dirent(*d, name, type, idx);
    if (!filter || filter(d))
      kept.push_back(d);
    else
      free(d);
  }
  auto** result = static_cast<dirent**>(malloc(sizeof(dirent*) * (kept.size() ? kept.size() : 1)));
  if (!result) {
    for (dirent* d : kept) free(d);
    errno = ENOMEM;
    return -1;
  }
  for (std::size_t i = 0; i < kept.size(); ++i) result[i] = kept[i];
  if (compar)
    qsort(result, kept.size(), sizeof(dirent*), reinterpret_cast<int (*)(const void*, const void*)>(compar));
  *out = result;
  return static_cast<int>(kept.size());
}

}  // namespace

extern "C" {

__attribute__((visibility("default"))) DIR* opendir(const char* path) {
  DIR* d = real::opendir(path);
  bool hide_real = false;
  if (!d) {
    const int e = errno;
    if (e != ENOENT || !virtual_only_dir(path) || !(d = real::opendir("/"))) {
      errno = e;
      return nullptr;
    }
    hide_real = true;
  }
  try {
    auto extra = extras_for(path);
    if (!extra.empty()) {
      std::lock_guard lock(g_mutex);
      if (!g_listings) g_listings = new std::unordered_map<DIR*, Listing>();
      Listing& l = (*g_listings)[d];
      l = Listing{};
      l.extra = std::move(extra);
      l.hide_real = hide_real;
    }
  } catch (...) {
    // Out of memory: list the real directory only (a stand-in has none: no directory then).
    if (hide_real) {
      real::closedir(d);
      errno = ENOMEM;
      return nullptr;
    }
  }
  return d;
}

__attribute__((visibility("default"))) dirent* readdir(DIR* dir) {
  try {
    return readdir_impl(dir);
  } catch (...) {
    return real::readdir(dir);
  }
}
__attribute__((visibility("default"))) dirent64* readdir64(DIR* dir) {
  static_assert(sizeof(dirent) == sizeof(dirent64), "dirent and dirent64 share a layout on LP64");
  return reinterpret_cast<dirent64*>(readdir(dir));
}

__attribute__((visibility("default"))) int closedir(DIR* dir) {
  if (g_listings) {
    std::lock_guard lock(g_mutex);
    g_listings->erase(dir);
  }
  return real::closedir(dir);
}

__attribute__((visibility("default"))) int scandir(const char* path, dirent*** out, int (*filter)(const dirent*),
                                                   int (*compar)(const dirent**, const dirent**)) {
  try {
    return scandir_impl(path, out, filter, compar);
  } catch (...) {
    errno = ENOMEM;
    return -1;
  }
}

__attribute__((visibility("default"))) int scandir64(const char* path, dirent64*** out, int (*filter)(const dirent64*),
                                                     int (*compar)(const dirent64**, const dirent64**)) {
  return scandir(path, reinterpret_cast<dirent***>(out), reinterpret_cast<int (*)(const dirent*)>(filter),
                 reinterpret_cast<int (*)(const dirent**, const dirent**)>(compar));
}

}  // extern "C"
