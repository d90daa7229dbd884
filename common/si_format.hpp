// Human-facing numbers: plain figures in messages, printouts and Markdown ("0.0123",
// "1.5e+06"), and quantities with SI prefixes ("43.2 nm", "131 nm/s", "3.2 fN"). Files stay in
// SI; only printouts and figure labels use these.
#pragma once

#include <string>

namespace swim {

/// `value` with `digits` significant digits, as printf's "%.<digits>g": "0.0123", "1.5e+06",
/// "3", "inf", "nan".
std::string significant(double value, int digits = 6);

/// `value` in the SI `unit` ("m", "m/s", "N", "s", "m^3"), rescaled by the SI prefix
/// (f, p, n, µ, m, -, k, M, G) that puts the mantissa in [1, 1000), with `digits`
/// significant digits. Volumes ("m^3") always print in µm³, the swimmers' scale, in plain
/// decimals down to 10⁻⁶ µm³ ("0.000718 µm³", "2 µm³"), so that every printout of a volume
/// has one unit. Zero prints as "0 <unit>"; non-finite values print as "n/a".
std::string si(double value, const std::string& unit, int digits = 3);

}  // namespace swim
