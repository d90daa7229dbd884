// Unit strings: conversion factors against hand-computed SI values, and every way a
// quantity string can be wrong.
#include <gtest/gtest.h>

#include "common/errors.hpp"
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
