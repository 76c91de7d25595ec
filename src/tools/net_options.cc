#include "net_options.h"

#include <stdexcept>

namespace partsim::tools {

int PortValue(const FlagValue& value) {
  return static_cast<int>(value.Integer(0, 65535, "(0 picks a free port)"));
}

void AddNetOptions(ArgParser* parser, NetOptions* options) {
  parser->Option("--port", [options](const FlagValue& v) { options->port = PortValue(v); });
  parser->Option("--address", [options](const FlagValue& v) { options->address = v.Text(); });
  parser->Option("--token", [options](const FlagValue& v) {
    options->token = v.NonEmpty("a non-empty token");
  });
  parser->Option("--allow-origin",
                 [options](const FlagValue& v) { options->allowed_origins.push_back(v.Text()); });
}

std::runtime_error CannotListen(const std::exception& error, const std::string& advice) {
  return std::runtime_error(std::string(error.what()) + "; " + advice);
}

}  // namespace partsim::tools
