// The run folder of an axi run, shared by the tier's two drivers (run_axi.cpp for the
// protocol-driven wall, run_prescribed_axi.cpp for the prescribed waves): the record's streamed
// files opened at the start, and the ending that completes the record, writes the folder
// (common/run_record.hpp: summary.json last) and hands the record over in the outcome.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "axi/run_axi.hpp"
#include "common/errors.hpp"
#include "common/run_record.hpp"

namespace swim::axi {

/// series.csv and radius.csv of `rec` streamed to out_dir as the run goes, within the control's
/// output limit; `rec` is attached to the stream, which the caller keeps for the run.
std::unique_ptr<record::RunStream> open_run_stream(record::RunRecord& rec, const std::string& out_dir,
                                                   const RunControlAxi& ctl);

/// The end of a run: the record completed by `fill(status, wall_time_s)` (status "ok", or
/// "failed: " and the failure's message), the folder written, the record detached from its
/// stream and moved into the outcome with the failure and `steps`.
RunOutcomeAxi finish_run(record::RunRecord& rec, const std::optional<NumericalError>& failure, double wall_time_s,
                         long steps, const std::string& out_dir, const scene::json& resolved,
                         const std::function<void(const std::string&, double)>& fill);

}  // namespace swim::axi
