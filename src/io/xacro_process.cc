#include "rigid_body_sim/io/xacro_process.h"

#include <stdlib.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "io/mesh_process_internal.h"

namespace rigid_body_sim::io {

using physics::Result;

bool LooksLikeXacro(const std::string& path, const std::string& text) {
  const std::string extension = ".xacro";
  if (path.size() >= extension.size() &&
      path.compare(path.size() - extension.size(), extension.size(), extension) == 0) {
    return true;
  }
  return text.find("xmlns:xacro") != std::string::npos;
}

Result<std::string> ExpandXacroFile(const std::string& path, const XacroRequest& request) {
  std::vector<std::string> arguments = {request.python,
                                        request.script,
                                        kXacroReplyFlag,
                                        std::to_string(request.limits.memory_bytes),
                                        internal::HexFloat(request.limits.cpu_seconds),
                                        path};
  arguments.insert(arguments.end(), request.args.begin(), request.args.end());
  MeshProcessLimits limits = request.limits;
  limits.helper_path = request.python;
  // HelperReply checks the file (regular, within max_file_bytes) before
  // the process starts, and turns a refusal, death or timeout into a message.
  Result<std::string> reply = internal::HelperReply(arguments, path, limits);
  if (!reply.ok()) return Result<std::string>::Error("xacro: " + reply.message());
  const std::string header = "urdf\n";
  if (reply->compare(0, header.size(), header) != 0) {
    return Result<std::string>::Error("xacro: the expander's reply has no 'urdf' header");
  }
  return reply->substr(header.size());
}

Result<std::string> ExpandXacroText(const std::string& text, const XacroRequest& request) {
  std::error_code error;
  const std::filesystem::path directory = std::filesystem::temp_directory_path(error);
  if (error) return Result<std::string>::Error("xacro: no temporary directory: " + error.message());
  std::string name = (directory / "rigid_body_sim_XXXXXX.xacro").string();
  // mkstemps: a new file of its own (mode 0600), never one that exists.
  const int fd = ::mkstemps(name.data(), 6);
  if (fd < 0) return Result<std::string>::Error("xacro: cannot make a temporary file");
  const bool written = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  ::close(fd);
  Result<std::string> expanded =
      written ? ExpandXacroFile(name, request)
              : Result<std::string>::Error("xacro: cannot write a temporary file");
  std::remove(name.c_str());
  return expanded;
}

}  // namespace rigid_body_sim::io
