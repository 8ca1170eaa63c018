#pragma once

#include <CLI/CLI.hpp>

#include "cli.hpp"

// Each subcommand registers itself on the app; when selected, its callback stores its exit code.
namespace smx::host {

void addPatternCommand(CLI::App& app, const CliStreams& io, int& exitCode);
void addSimCommand(CLI::App& app, const CliStreams& io, int& exitCode);
void addDemuxCommand(CLI::App& app, const CliStreams& io, int& exitCode);
void addDecodeCommand(CLI::App& app, const CliStreams& io, int& exitCode);
void addCheckCommand(CLI::App& app, const CliStreams& io, int& exitCode);
void addEvalCommand(CLI::App& app, const CliStreams& io, int& exitCode);
void addInfoCommand(CLI::App& app, const CliStreams& io, int& exitCode);
void addStreamCommand(CLI::App& app, const CliStreams& io, int& exitCode);
void addCalibrateCommand(CLI::App& app, const CliStreams& io, int& exitCode);
void addCaptureCommand(CLI::App& app, const CliStreams& io, int& exitCode);
void addConfigCommand(CLI::App& app, const CliStreams& io, int& exitCode);
void addKeygenCommand(CLI::App& app, const CliStreams& io, int& exitCode);
void addBundleCommand(CLI::App& app, const CliStreams& io, int& exitCode);
void addVerifyBundleCommand(CLI::App& app, const CliStreams& io, int& exitCode);
void addPairCommand(CLI::App& app, const CliStreams& io, int& exitCode);
void addFlashCommand(CLI::App& app, const CliStreams& io, int& exitCode);
void addTurntableCommand(CLI::App& app, const CliStreams& io, int& exitCode);
void addFuseCommand(CLI::App& app, const CliStreams& io, int& exitCode);
void addScanCommand(CLI::App& app, const CliStreams& io, int& exitCode);
void addViewCommand(CLI::App& app, const CliStreams& io, int& exitCode);

}  // namespace smx::host
