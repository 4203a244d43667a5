// One run of an asset importer in a child process, so that a crash, a hang
// or a memory blow-up of a parser of hostile input (assimp, OpenVDB) costs
// the upload, never the server.  The mesh and the volume imports
// (mesh_import_process.h, volume_import_process.h) are this plus their own
// arguments and their strict decoding of what the child wrote.
//
//   command      the child's program and first arguments, e.g.
//                {"/proc/self/exe", "import-mesh"}; the child gets `args`,
//                then IN and OUT (file names in a fresh scratch directory)
//   work_dir     where the input, output and stderr files live meanwhile
//                (one fresh directory per import, removed after)
//   timeout      wall clock; the child is killed (SIGKILL) beyond
//   cpu_seconds  RLIMIT_CPU of the child
//   memory_bytes RLIMIT_AS of the child (address space, so it bounds what
//                the parser can allocate)
//
// fork() is followed only by async-signal-safe calls (dup2, setrlimit,
// close_range, chdir, execv).  The child's protocol: exit 0 with OUT
// written, 1 with one sentence for the client on stderr, 2 for a usage
// error (126, 127: it could not start).
#pragma once
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace skyfarm::server {

struct ImportChildOptions {
  std::vector<std::string> command;
  std::string work_dir;
  std::chrono::milliseconds timeout = std::chrono::seconds(30);
  unsigned cpu_seconds = 20;
  std::uint64_t memory_bytes = std::uint64_t{4} << 30;
};

struct ImportChildResult {
  bool ok = false;
  std::string output;  // OUT's bytes, when ok (untrusted: decode strictly)
  std::string error;   // one sentence for the client, when not ok
};

// `what` names the import in messages ("mesh": "the mesh import took longer
// than ...").  Throws std::runtime_error when the importer could not run at
// all (a server fault, not the file's).
ImportChildResult run_import_child(std::string_view bytes, const std::vector<std::string>& args,
                                   const ImportChildOptions& options, std::string_view what);

// For the child's side: the whole file, or false.
bool read_whole_file(const std::string& path, std::string* bytes);
bool write_whole_file(const std::string& path, std::string_view bytes);

// For the child's side: an option that takes a value ("--grid NAME");
// `set` returns false when the value is not one (a usage error).
struct ImportOption {
  std::string_view name;
  std::function<bool(const std::string& value)> set;
};

// For the child's side: `args` as `options` in any order and the file names
// IN and OUT (left empty when missing: the command says its usage).  An
// option last on the line, without its value, counts as a file name.
// Returns 0, or 2 after a usage error (a stray argument is named on stderr,
// as `command`'s: "import-mesh").
int parse_import_args(const std::vector<std::string>& args, std::string_view command,
                      const std::vector<ImportOption>& options, std::string* in, std::string* out);

// A count option's value: all of `s` a decimal number, else false.
template <class Unsigned>
bool parse_count(const std::string& s, Unsigned* value) {
  try {
    std::size_t used = 0;
    *value = std::stoull(s, &used);
    return used == s.size();
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace skyfarm::server
