// skyfarm-server: the HTTP API and ZeroMQ broker of the render farm.
// The farm itself arrives with issue 4; this program exists so the layout and
// the server's dependencies (cpp-httplib, cppzmq, SQLite) are built from the start.
#include <iostream>
#include <string>

int main(int argc, char** argv) {
  const std::string arg = argc > 1 ? argv[1] : "";
  if (arg == "--version") {
    std::cout << "skyfarm " << SKYFARM_VERSION << "\n";
    return 0;
  }
  std::cerr << "skyfarm-server: the render farm is not implemented yet (issue 4).\n"
               "Use `skyfarm-worker info REQUEST.json` to inspect a request's sky.\n";
  return 2;
}
