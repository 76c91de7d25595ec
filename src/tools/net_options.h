// The network flags of the commands that serve (partsim serve, partsim view): --port, --address,
// --token and --allow-origin, declared and checked in one place.
#pragma once

#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include "arg_parser.h"

namespace partsim::tools {

/// Where a server listens and whom it lets in, as the flags give it.
struct NetOptions {
  std::string address = "127.0.0.1";         ///< --address: interface (an address or a host name)
  int port = 0;                              ///< --port: TCP port; 0 picks a free one
  std::string token;                         ///< --token: what clients must send first; "" for none
  std::vector<std::string> allowed_origins;  ///< --allow-origin, each time it is given

  /// Copies the four into a server's options (RosbridgeOptions, ViewerOptions).
  template <typename ServerOptions>
  void ApplyTo(ServerOptions* o) const {
    o->address = address;
    o->port = port;
    o->auth_token = token;
    o->allowed_origins = allowed_origins;
  }
};

/// A port flag's value: a whole number from 0 to 65535, 0 picking a free port.
int PortValue(const FlagValue& value);

/// Declares --port, --address, --token and --allow-origin on `parser`; their values go to
/// `options` (which keeps its defaults for flags not given). --token refuses an empty token;
/// --allow-origin adds up.
void AddNetOptions(ArgParser* parser, NetOptions* options);

/// The error of a server that could not start listening, followed by how to pick another port:
/// "<error>; choose another port with --port P, or --port 0 for a free one" (`advice` replaces
/// the text after "; ").
std::runtime_error CannotListen(
    const std::exception& error,
    const std::string& advice = "choose another port with --port P, or --port 0 for a free one");

}  // namespace partsim::tools
