// Inputs that could block or never end: a device, a directory, a socket, a FIFO that nobody
// writes to are refused with the reason; a FIFO whose writer writes is read like a file.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <string>
#include <thread>

#include "spi/input_file.hpp"

namespace l6470emu {
namespace {

namespace fs = std::filesystem;

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("l6470emu-input-" + std::to_string(getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

std::string refusal(const std::string& path, int wait_ms = 100) {
  std::string why;
  const int fd = open_input_file(path, why, wait_ms);
  if (fd >= 0) ::close(fd);
  return fd < 0 ? why : "opened";
}

TEST(InputFile, ADeviceADirectoryAndAMissingFileAreRefusedWithTheReason) {
  EXPECT_EQ(refusal("/dev/zero"), "is a device, not a file: it could block or never end");
  EXPECT_EQ(errno, 0);
  EXPECT_EQ(refusal("/tmp"), "is a directory");
  EXPECT_EQ(refusal("/nonexistent/x"), "cannot be read (No such file or directory)");
  EXPECT_EQ(errno, ENOENT);
}

TEST(InputFile, ASocketIsRefused) {
  TempDir dir;
  const std::string path = (dir.path / "s").string();
  const int s = ::socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un a{};
  a.sun_family = AF_UNIX;
  path.copy(a.sun_path, sizeof a.sun_path - 1);
  ASSERT_EQ(::bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  EXPECT_EQ(refusal(path), "is a socket, not a file");
  ::close(s);
}

TEST(InputFile, AFifoNobodyWritesToIsRefusedAfterTheWait) {
  TempDir dir;
  const std::string path = (dir.path / "f").string();
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  EXPECT_EQ(refusal(path, 300), "is a FIFO that nothing wrote to within 0.3 s");
}

TEST(InputFile, AFifoWhoseWriterWritesIsReadToTheEnd) {
  TempDir dir;
  const std::string path = (dir.path / "f").string();
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  std::thread writer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));  // after the reader opened it
    FILE* f = std::fopen(path.c_str(), "w");
    std::fputs("chips=L6470\n", f);
    std::fclose(f);
  });
  std::string why;
  const int fd = open_input_file(path, why, 5000);
  ASSERT_GE(fd, 0) << why;
  std::string text;
  char b[64];
  for (ssize_t n; (n = ::read(fd, b, sizeof b)) > 0;) text.append(b, static_cast<std::size_t>(n));
  ::close(fd);
  writer.join();
  EXPECT_EQ(text, "chips=L6470\n");
}

}  // namespace
}  // namespace l6470emu
