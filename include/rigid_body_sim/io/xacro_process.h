// xacro descriptions expanded out of process: the package's own expander
// (scripts/xacro, Python) runs per description under the mesh helper's
// limits (address space, CPU time, wall time), so a macro that recurses or
// a property that grows without end costs the node nothing but a refusal.
// ROS-free.
#ifndef RIGID_BODY_SIM_IO_XACRO_PROCESS_H_
#define RIGID_BODY_SIM_IO_XACRO_PROCESS_H_

#include <string>
#include <vector>

#include "rigid_body_sim/io/mesh_process.h"
#include "rigid_body_sim/physics/result.h"

namespace rigid_body_sim::io {

// A description is xacro when its file name ends in ".xacro" or its text
// declares the xacro namespace (xmlns:xacro=...).
bool LooksLikeXacro(const std::string& path, const std::string& text);

struct XacroRequest {
  std::string script;  // the expander: scripts/xacro, run by python3
  std::string python = "/usr/bin/python3";
  std::vector<std::string> args;  // name:=value, as on xacro's command line
  MeshProcessLimits limits;       // memory, CPU and file size, as for meshes
};

// The URDF that the xacro file at `path` expands to with `request.args`, or
// the expander's error (it names the file, the line and the construct),
// its death or its timeout.
physics::Result<std::string> ExpandXacroFile(const std::string& path, const XacroRequest& request);

// As ExpandXacroFile for a description given as text (a spawn request's
// urdf field): written to a private temporary file first, so its includes
// resolve only through $(find ...) or absolute paths.
physics::Result<std::string> ExpandXacroText(const std::string& text, const XacroRequest& request);

// The expander's protocol: run as `python3 SCRIPT --rbs-reply MEMORY_BYTES
// CPU_SECONDS FILE ARGS...`, it limits itself and writes "urdf\n" and the
// URDF, or "error <why>\n".
inline constexpr char kXacroReplyFlag[] = "--rbs-reply";

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_IO_XACRO_PROCESS_H_
