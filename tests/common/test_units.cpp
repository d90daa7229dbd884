// Unit strings: conversion factors against hand-computed SI values, and every way a
// quantity string can be wrong; and the SI-prefixed printouts.
#include <gtest/gtest.h>

#include <cmath>

#include "common/errors.hpp"
#include "common/si_format.hpp"
#include "common/units.hpp"

using swim::InputError;
using swim::units::parse;

TEST(Units, ConvertsPrefixedAndCompoundUnitsToSI) {
  EXPECT_NEAR(parse("k", "0.125 um", "m").si, 1.25e-7, 1e-21);
  EXPECT_NEAR(parse("k", "1.2e-3 Pa*s", "Pa*s").si, 1.2e-3, 1e-18);
  EXPECT_NEAR(parse("k", "0.012 g/(cm*s)", "Pa*s").si, 1.2e-3, 1e-18);  // the paper's viscosity
  EXPECT_NEAR(parse("k", "1.00 g/cm^3", "kg/m^3").si, 1000.0, 1e-9);    // the paper's density
  EXPECT_NEAR(parse("k", "5.5e-8 N/m", "N/m").si, 5.5e-8, 1e-22);
  EXPECT_NEAR(parse("k", "2.25e-3 ug/um", "kg/m").si, 2.25e-6, 1e-20);
  EXPECT_NEAR(parse("k", "0.1 pN", "N").si, 1e-13, 1e-27);
  EXPECT_NEAR(parse("k", "0.01 ms", "s").si, 1e-5, 1e-19);
  EXPECT_NEAR(parse("k", "4e6 Pa/m", "Pa/m").si, 4e6, 1e-6);
  EXPECT_NEAR(parse("k", "10 um/s", "m/s").si, 1e-5, 1e-19);
}

TEST(Units, RejectsMalformedQuantitiesNamingTheKey) {
  for (const char* bad : {"0.125", "um", "", "0.125 furlongz", "1.2e-3 Pa", "nan m", "5 degC"}) {
    try {
      parse("swimmer.radius", bad, std::string(bad) == "5 degC" ? "K" : std::string(bad) == "1.2e-3 Pa" ? "Pa*s" : "m");
      FAIL() << "accepted '" << bad << "'";
    } catch (const InputError& e) {
      EXPECT_EQ(e.key(), "swimmer.radius");
      EXPECT_NE(std::string(e.what()).find("swimmer.radius"), std::string::npos);
    }
  }
}

TEST(Units, ToBaseGivesSIValueAndUnit) {
  auto [v, u] = swim::units::to_base("k", "0.2 um");
  EXPECT_NEAR(v, 2e-7, 1e-21);
  EXPECT_EQ(u, "m");
}

// Human-facing numbers: the SI prefix that puts the mantissa in [1, 1000), µ (not u), and
// volumes in one unit, µm³, in plain decimals rather than in e-notation.
TEST(SiFormat, PrefixesMantissasAndVolumes) {
  EXPECT_EQ(swim::si(4.32e-8, "m"), "43.2 nm");
  EXPECT_EQ(swim::si(1.31e-7, "m/s"), "131 nm/s");
  EXPECT_EQ(swim::si(2.5e-6, "m/s"), "2.5 \u00b5m/s");
  EXPECT_EQ(swim::si(-3.2e-15, "N"), "-3.2 fN");
  EXPECT_EQ(swim::si(0.134, "s"), "134 ms");
  // volumes: one unit, µm³, for every printout (two runs' pumped volumes compare at a glance)
  EXPECT_EQ(swim::si(0.0, "m^3"), "0 \u00b5m\u00b3");
  EXPECT_EQ(swim::si(-0.0, "m^3"), "0 \u00b5m\u00b3");  // a run stopped at t = 0: no "-0"
  EXPECT_EQ(swim::si(-0.0, "m"), "0 m");
  EXPECT_EQ(swim::si(7.1823e-22, "m^3"), "0.000718 \u00b5m\u00b3");
  EXPECT_EQ(swim::si(-7.1823e-22, "m^3"), "-0.000718 \u00b5m\u00b3");
  EXPECT_EQ(swim::si(3.82e-21, "m^3"), "0.00382 \u00b5m\u00b3");
  EXPECT_EQ(swim::si(9.62e-22, "m^3"), "0.000962 \u00b5m\u00b3");
  EXPECT_EQ(swim::si(3.4e-25, "m^3"), "3.4e-07 \u00b5m\u00b3");  // below 10⁻⁶ µm³
  EXPECT_EQ(swim::si(2.0e-18, "m^3"), "2 \u00b5m\u00b3");
  EXPECT_EQ(swim::si(1.234567e-24, "m^3", 5), "0.0000012346 \u00b5m\u00b3");
  EXPECT_EQ(swim::si(1.0e-27, "m^3"), "1e-09 \u00b5m\u00b3");
  EXPECT_EQ(swim::si(std::nan(""), "m"), "n/a");
}
