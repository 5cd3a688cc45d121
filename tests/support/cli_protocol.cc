#include "tests/support/cli_protocol.h"

#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>

namespace linetrack::test_support {

namespace {

bool SendAll(int fd, const void* data, size_t size) {
  const char* bytes = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t sent = send(fd, bytes, size, MSG_NOSIGNAL);
    if (sent < 0 && errno == EINTR) continue;
    if (sent <= 0) return false;
    bytes += sent;
    size -= static_cast<size_t>(sent);
  }
  return true;
}

bool ReceiveAll(int fd, void* data, size_t size) {
  char* bytes = static_cast<char*>(data);
  while (size > 0) {
    const ssize_t got = recv(fd, bytes, size, 0);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) return false;
    bytes += got;
    size -= static_cast<size_t>(got);
  }
  return true;
}

bool SendStrings(int fd, const std::vector<std::string>& strings) {
  const uint32_t count = static_cast<uint32_t>(strings.size());
  if (!SendAll(fd, &count, sizeof(count))) return false;
  for (const std::string& text : strings) {
    const uint32_t size = static_cast<uint32_t>(text.size());
    if (!SendAll(fd, &size, sizeof(size)) || !SendAll(fd, text.data(), text.size())) return false;
  }
  return true;
}

bool ReceiveStrings(int fd, std::vector<std::string>* strings) {
  uint32_t count = 0;
  if (!ReceiveAll(fd, &count, sizeof(count))) return false;
  strings->assign(count, std::string());
  for (std::string& text : *strings) {
    uint32_t size = 0;
    if (!ReceiveAll(fd, &size, sizeof(size))) return false;
    text.resize(size);
    if (size > 0 && !ReceiveAll(fd, text.data(), size)) return false;
  }
  return true;
}

}  // namespace

bool SendRequest(int fd, const CliRequest& request) {
  return SendStrings(fd, request.argv) && SendStrings(fd, request.environment) &&
         SendStrings(fd, {request.working_dir, request.stdout_path, request.stderr_path});
}

bool ReceiveRequest(int fd, CliRequest* request) {
  std::vector<std::string> paths;
  if (!ReceiveStrings(fd, &request->argv) || !ReceiveStrings(fd, &request->environment) ||
      !ReceiveStrings(fd, &paths) || paths.size() != 3 || request->argv.empty()) {
    return false;
  }
  request->working_dir = paths[0];
  request->stdout_path = paths[1];
  request->stderr_path = paths[2];
  return true;
}

bool SendExitCode(int fd, int code) {
  const int32_t value = code;
  return SendAll(fd, &value, sizeof(value));
}

bool ReceiveExitCode(int fd, int* code) {
  int32_t value = 0;
  if (!ReceiveAll(fd, &value, sizeof(value))) return false;
  *code = value;
  return true;
}

}  // namespace linetrack::test_support
