#include "axi/run_folder_axi.hpp"

namespace swim::axi {

std::unique_ptr<record::RunStream> open_run_stream(record::RunRecord& rec, const std::string& out_dir,
                                                   const RunControlAxi& ctl) {
  auto stream = std::make_unique<record::RunStream>(out_dir, series_columns());
  stream->limit(ctl.max_output_bytes);
  rec.attach(stream.get());
  return stream;
}

RunOutcomeAxi finish_run(record::RunRecord& rec, const std::optional<NumericalError>& failure, double wall_time_s,
                         long steps, const std::string& out_dir, const scene::json& resolved,
                         const std::function<void(const std::string&, double)>& fill) {
  RunOutcomeAxi res;
  res.failed = failure.has_value();
  res.message = failure ? failure->what() : "";
  fill(failure ? "failed: " + std::string(failure->what()) : "ok", wall_time_s);
  res.summary = record::write_run(out_dir, rec, resolved);
  res.steps = steps;
  rec.attach(nullptr);
  res.record = std::move(rec);
  return res;
}

}  // namespace swim::axi
