#pragma once
/// The command-line options that choose a device backend (session::make_backend builds it).
#include <CLI/CLI.hpp>

#include "spidar/session/device_backends.hpp"

namespace spidar::app {

using session::BackendArgs;
using session::make_backend;
using session::make_simulated;

void add_backend_options(CLI::App& cmd, BackendArgs& a);

}  // namespace spidar::app
