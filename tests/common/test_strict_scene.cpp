// Strict scene reading: hostile and odd input is rejected with an InputError naming the key
// (exit 2 through the executable, nothing written), never a crash or an internal error.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "app/scene_checks.hpp"
#include "axi/scene_axi.hpp"
#include "common/errors.hpp"
#include "common/scene.hpp"
#include "common/scene_shared.hpp"
#include "common/strict_json.hpp"
#include "common/units.hpp"
#include "full3d/scene3d.hpp"
#include "full3d/scene3d_keys.hpp"
#include "reduced1d/scene1d.hpp"
#include "reduced1d/scene1d_keys.hpp"

namespace fs = std::filesystem;
using swim::InputError;
using swim::scene::json;

namespace {

fs::path tmpdir(const std::string& tag) {
  const fs::path d = fs::temp_directory_path() / ("swim_strict_" + tag + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

fs::path write(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

// The key of the InputError thrown by f, or "(accepted)" / "(other exception)".
template <class F>
std::string rejected_key(F&& f, std::string* message = nullptr) {
  try {
    f();
  } catch (const InputError& e) {
    if (message) *message = e.what();
    return e.key();
  } catch (...) {
    return "(other exception)";
  }
  return "(accepted)";
}

std::string load_key(const fs::path& p, std::string* message = nullptr) {
  return rejected_key([&] { swim::scene::load_file(p.string()); }, message);
}

std::string read1d_key(const json& s, std::string* message = nullptr) {
  return rejected_key(
      [&] {
        json r;
        swim::reduced1d::read_scene(s, r);
        swim::app::check_other_tier(s, "1d");
      },
      message);
}

struct Cli {
  int code = -1;
  std::string err;
};

Cli swim_cli(const std::string& args, const fs::path& dir) {
  const fs::path err = dir / "stderr.txt";
  const std::string cmd = std::string("\"") + SWIM_BINARY_DIR + "/bin/swim\" " + args + " > /dev/null 2> \"" +
                          err.string() + "\"";
  const int status = std::system(cmd.c_str());
  Cli c;
  c.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(err);
  c.err.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return c;
}

}  // namespace

TEST(StrictJson, ANestingBombIsRejectedWithoutRecursion) {
  const fs::path d = tmpdir("bomb");
  std::string bomb;
  for (int i = 0; i < 60000; ++i) bomb += "{\"a\":";
  bomb += "1";
  bomb += std::string(60000, '}');
  std::string msg;
  EXPECT_EQ(load_key(write(d / "bomb.json", bomb), &msg).substr(0, 4), "a.a.");
  EXPECT_NE(msg.find("nested deeper than 64"), std::string::npos) << msg;
  // arrays too, and through the executable: exit 2, nothing written
  write(d / "arrays.json", std::string(60000, '[') + std::string(60000, ']'));
  for (const char* f : {"bomb.json", "arrays.json"}) {
    const Cli c = swim_cli("run \"" + (d / f).string() + "\" --out \"" + (d / "out").string() + "\"", d);
    EXPECT_EQ(c.code, 2) << f << ": " << c.err;
    EXPECT_FALSE(fs::exists(d / "out"));
  }
  // 64 levels are fine
  std::string ok;
  for (int i = 0; i < 63; ++i) ok += "{\"a\":";
  ok += "1" + std::string(63, '}');
  EXPECT_NO_THROW(swim::strict_json::parse(ok, "scene"));
  fs::remove_all(d);
}

TEST(StrictJson, NumbersThatDoNotFitADoubleAreRejectedNamingTheKey) {
  for (const char* n : {"1e400", "-1e400", "1e-400", "1" /* + 400 zeros below */}) {
    std::string num = n;
    if (num == "1") num += std::string(400, '0');
    std::string msg;
    const std::string text = R"({"numerics1d": {"rtol": )" + num + "}}";
    EXPECT_EQ(rejected_key([&] { swim::strict_json::parse(text, "scene"); }, &msg), "numerics1d.rtol") << num;
    EXPECT_NE(msg.find("double"), std::string::npos) << msg;
  }
  // within range: fine
  EXPECT_NO_THROW(swim::strict_json::parse(R"({"a": 1e300, "b": 0.0e-400, "c": 2.3e-308})", "scene"));
  // an integer beyond the reader's range is not wrapped around
  EXPECT_EQ(read1d_key(json::parse(R"({"numerics1d": {"cells": 18446744073709551615}})")), "numerics1d.cells");
}

TEST(StrictJson, DuplicateKeysAreRejectedAtAnyDepth) {
  std::string msg;
  EXPECT_EQ(rejected_key([] { swim::strict_json::parse(R"({"name": "a", "name": "b"})", "scene"); }, &msg), "name");
  EXPECT_NE(msg.find("twice"), std::string::npos);
  EXPECT_EQ(rejected_key([] {
              swim::strict_json::parse(R"({"swimmer": {"radius": "1 um", "length": "2 um", "radius": "1 um"}})", "s");
            }),
            "swimmer.radius");
  // the same key in two different objects is fine
  EXPECT_NO_THROW(swim::strict_json::parse(R"({"a": {"x": 1}, "b": {"x": 1}, "c": [{"x": 1}, {"x": 2}]})", "s"));
}

TEST(StrictJson, TextThatIsNotUtf8IsRejectedAndNeverEchoedRaw) {
  const fs::path d = tmpdir("utf8");
  std::string msg;
  EXPECT_EQ(load_key(write(d / "latin1.json", "{\"description\": \"caf\xe9\"}"), &msg), "description");
  EXPECT_EQ(msg.find('\xe9'), std::string::npos) << "raw byte echoed";
  EXPECT_NE(msg.find("\\xE9"), std::string::npos) << msg;
  // overlong encoding and a lone surrogate
  EXPECT_EQ(load_key(write(d / "overlong.json", "{\"name\": \"\xc0\xaf\"}")), "name");
  EXPECT_EQ(load_key(write(d / "surrogate.json", "{\"name\": \"\xed\xa0\x80\"}")), "name");
  // UTF-8 text is fine
  EXPECT_EQ(load_key(write(d / "ok.json", "{\"description\": \"0.125 \xc2\xb5m, caf\xc3\xa9\"}")), "(accepted)");
  // --set with bytes that are not UTF-8
  json s = json::object();
  EXPECT_EQ(rejected_key([&] { swim::scene::apply_override(s, "description=caf\xe9"); }), "--set");
  // through the executable
  const Cli c = swim_cli("run \"" + (d / "latin1.json").string() + "\" --out \"" + (d / "out").string() + "\"", d);
  EXPECT_EQ(c.code, 2) << c.err;
  EXPECT_FALSE(fs::exists(d / "out"));
  fs::remove_all(d);
}

TEST(StrictUnits, ExactlyOneDecimalNumberAndOneUnit) {
  using swim::units::parse;
  for (const char* bad : {"0.1 0.2 um", "0.1 um 2", "0.1 um*2", "0.1 um/1000", "2 3", "0x1p-3 um", "0X10 um", "inf um",
                          "nan um", "1e400 um", "1e-400 um", "1.5.2 um", "um", "1 um @ 2", "1 s since 2000-01-01",
                          "--1 um", "+-1 um", ". um"}) {
    const std::string key = rejected_key([&] { parse("swimmer.radius", bad, bad[0] == '1' && bad[2] == 's' ? "s" : "m"); });
    EXPECT_EQ(key, "swimmer.radius") << "accepted '" << bad << "'";
  }
  std::string msg;
  rejected_key([] { parse("k", "0.1 0.2 um", "m"); }, &msg);
  EXPECT_NE(msg.find("exactly one number"), std::string::npos) << msg;
  rejected_key([] { parse("k", "0x1p-3 um", "m"); }, &msg);
  EXPECT_NE(msg.find("hexadecimal"), std::string::npos) << msg;
  // accepted forms, values as documented
  EXPECT_NEAR(parse("k", "0.125 um", "m").si, 1.25e-7, 1e-21);
  EXPECT_NEAR(parse("k", ".5 um", "m").si, 5e-7, 1e-21);
  EXPECT_NEAR(parse("k", "+2E-3 Pa*s", "Pa*s").si, 2e-3, 1e-18);
  EXPECT_NEAR(parse("k", "1 kg/(m^2*s)", "kg/(m^2*s)").si, 1.0, 1e-15);
  EXPECT_NEAR(parse("k", "1 g/cm^3", "kg/m^3").si, 1000.0, 1e-9);
  EXPECT_NEAR(parse("k", "3 m2", "m^2").si, 3.0, 1e-15);
  EXPECT_NEAR(parse("k", "-4 Pa", "Pa").si, -4.0, 1e-15);
  // through the executable: exit 2 naming the key
  const fs::path d = tmpdir("units");
  write(d / "s.json", R"({"swimmer": {"radius": "0.1 0.2 um"}})");
  const Cli c = swim_cli("run \"" + (d / "s.json").string() + "\" --out \"" + (d / "out").string() + "\"", d);
  EXPECT_EQ(c.code, 2);
  EXPECT_NE(c.err.find("'swimmer.radius'"), std::string::npos) << c.err;
  EXPECT_FALSE(fs::exists(d / "out"));
  fs::remove_all(d);
}

TEST(StrictScene, SetPathsWithEmptyComponentsAreRejected) {
  for (const char* a : {"swimmer.radius.=1 um", ".swimmer=1", "swimmer..radius=1 um", "=1", "."}) {
    json s = json::object();
    EXPECT_EQ(rejected_key([&] { swim::scene::apply_override(s, a); }), "--set") << a;
    EXPECT_EQ(s, json::object()) << a << " changed the scene";
  }
  // strict JSON applies to --set values too: a duplicate key is an error, not a string
  json s = json::object();
  EXPECT_NE(rejected_key([&] { swim::scene::apply_override(s, R"(full3d={"dt": "1 ms", "dt": "2 ms"})"); }), "(accepted)");
  // text that is not JSON stays a string
  swim::scene::apply_override(s, "swimmer.radius=0.2 um");
  EXPECT_EQ(s["swimmer"]["radius"], "0.2 um");
}

TEST(StrictScene, ASceneThatIsNotARegularFileIsRejected) {
  const fs::path d = tmpdir("notfile");
  EXPECT_EQ(load_key(d), "scene");
  EXPECT_EQ(load_key(d / "missing.json"), "scene");
  EXPECT_EQ(load_key("/dev/null"), "scene");
  std::string msg;
  load_key(d, &msg);
  EXPECT_NE(msg.find("directory"), std::string::npos) << msg;
  const Cli c = swim_cli("run \"" + d.string() + "\" --out \"" + (d / "out").string() + "\"", d);
  EXPECT_EQ(c.code, 2) << c.err;
  EXPECT_EQ(c.err.find("internal error"), std::string::npos) << c.err;
  fs::remove_all(d);
}

TEST(StrictScene, NamesNeverLeaveTheOutputFolder) {
  for (const char* bad : {"../../x", "/etc/x", "a/b", "..", ".hidden", "-rf", "", "a\\b", "x\ny"}) {
    EXPECT_EQ(read1d_key({{"name", bad}}), "name") << bad;
    json r;
    EXPECT_EQ(rejected_key([&] { swim::full3d::read_scene3d({{"name", bad}}, r); }), "name") << bad;
  }
  EXPECT_EQ(read1d_key({{"name", "paper_amplitude_0.35"}}), "(accepted)");
  // through the executable: nothing is created outside out/
  const fs::path d = tmpdir("name");
  write(d / "s.json", R"({"name": "../../escaped"})");
  const std::string cmd = "cd \"" + d.string() + "\" && mkdir -p a/b && cd a/b && \"" + SWIM_BINARY_DIR +
                          "/bin/swim\" run ../../s.json > /dev/null 2>&1";
  const int status = std::system(cmd.c_str());
  EXPECT_EQ(WEXITSTATUS(status), 2);
  EXPECT_FALSE(fs::exists(d / "escaped-1d"));
  EXPECT_FALSE(fs::exists(d / "a" / "escaped-1d"));
  EXPECT_FALSE(fs::exists(d / "a" / "b" / "out"));
  fs::remove_all(d);
}

TEST(StrictScene, EchoedValuesAreShortened) {
  const std::string huge(2000000, 'x');
  std::string msg;
  EXPECT_EQ(read1d_key({{"swimmer", {{"radius", "1 " + huge}}}}, &msg), "swimmer.radius");
  EXPECT_LT(msg.size(), 3000u);
  EXPECT_NE(msg.find("bytes"), std::string::npos) << msg.substr(0, 300);
  EXPECT_EQ(read1d_key({{"swimmer", {{huge, 1}}}}, &msg), "swimmer." + huge);
  EXPECT_LT(msg.size(), 3000u);
  EXPECT_EQ(read1d_key({{"description", json::array({huge, huge})}}, &msg), "description");
  EXPECT_LT(msg.size(), 3000u);
  // control characters are shown escaped
  EXPECT_EQ(read1d_key({{"swimmer", {{"radius", "1 \x1b[2Jum"}}}}, &msg), "swimmer.radius");
  EXPECT_EQ(msg.find('\x1b'), std::string::npos);
}

TEST(StrictScene, TheOtherTiersSectionsMustBeWellFormed) {
  // 1D run: full3d must be an object of 3D keys with values of the right kind
  for (const char* bad : {R"({"full3d": "junk"})", R"({"full3d": {"dtt": "1 ms"}})", R"({"full3d": {"dt": 5}})",
                          R"({"full3d": {"dt": "1 m"}})", R"({"full3d": {"grid": {"cells_across": "32"}}})",
                          R"({"full3d": {"container": {"kind": "sphere"}}})", R"({"full3d": {"output": []}})"}) {
    const std::string key = read1d_key(json::parse(bad));
    EXPECT_EQ(key.rfind("full3d", 0), 0u) << bad << " -> " << key;
  }
  EXPECT_EQ(read1d_key(json::parse(R"({"full3d": {"dt": "0.5 ms", "grid": {"cells_across": 16}}})")), "(accepted)");
  // 3D run: model1d and numerics1d
  for (const char* bad : {R"({"model1d": "junk"})", R"({"model1d": {"closure": "nope"}})",
                          R"({"numerics1d": {"cells": 2.5}})", R"({"numerics1d": {"cell": 64}})"}) {
    const std::string key = rejected_key([&] { swim::app::check_other_tier(json::parse(bad), "3d"); });
    EXPECT_TRUE(key.rfind("model1d", 0) == 0 || key.rfind("numerics1d", 0) == 0) << bad << " -> " << key;
  }
  // through the executable
  const fs::path d = tmpdir("other");
  write(d / "s.json", R"({"full3d": "junk"})");
  const Cli c = swim_cli("run \"" + (d / "s.json").string() + "\" --out \"" + (d / "out").string() + "\"", d);
  EXPECT_EQ(c.code, 2);
  EXPECT_NE(c.err.find("'full3d'"), std::string::npos) << c.err;
  EXPECT_FALSE(fs::exists(d / "out"));
  fs::remove_all(d);
}

namespace {
// Leaves of a schema as dotted paths with their kind.
void leaves(const json& schema, const std::string& path, std::vector<std::pair<std::string, std::string>>& out) {
  for (auto it = schema.begin(); it != schema.end(); ++it) {
    const std::string p = path.empty() ? it.key() : path + "." + it.key();
    if (it.value().is_object())
      leaves(it.value(), p, out);
    else
      out.emplace_back(p, it.value().get<std::string>());
  }
}
}  // namespace

TEST(StrictScene, SectionKeyListsMatchTheTierReaders) {
  // Every key a tier reader writes into its resolved section is in the list the other tier
  // checks against, and every listed key is one the reader reads (a junk value of the wrong
  // kind is rejected naming that very key, not as unknown).
  std::vector<std::pair<std::string, std::string>> keys3d, keys1d;
  leaves(swim::full3d::section_keys(), "full3d", keys3d);
  leaves(swim::reduced1d::section_keys(), "", keys1d);
  const fs::path scenes = fs::path(SWIM_SOURCE_DIR) / "data" / "scenes";
  for (const auto& e : fs::directory_iterator(scenes)) {
    const json sc = swim::scene::load_file(e.path().string());
    json r1, r3;
    swim::reduced1d::read_scene(sc, r1);
    EXPECT_NO_THROW(swim::app::check_other_tier(r1, "3d")) << e.path();
    for (const char* s : {"model1d", "numerics1d"})
      EXPECT_NO_THROW(swim::scene::check_section(r1[s], s, swim::reduced1d::section_keys()[s])) << e.path();
    if (sc.contains("full3d")) {
      swim::full3d::read_scene3d(sc, r3);
      EXPECT_NO_THROW(swim::scene::check_section(r3["full3d"], "full3d", swim::full3d::section_keys())) << e.path();
      EXPECT_NO_THROW(swim::app::check_other_tier(r3, "1d")) << e.path();
    }
  }
  const json junk = json::array({1});
  for (const auto& [path, kind] : keys3d) {
    json sc = json::object();
    if (path == "full3d.grid.cell_size") sc["full3d"]["grid"] = json::object();
    swim::scene::apply_override(sc, path + "=[1]");
    json r;
    std::string msg;
    EXPECT_EQ(rejected_key([&] { swim::full3d::read_scene3d(sc, r); }, &msg), path) << msg;
    EXPECT_EQ(msg.find("unknown key"), std::string::npos) << msg;
  }
  for (const auto& [path, kind] : keys1d) {
    json sc = json::object();
    if (path.rfind("model1d.paper.", 0) == 0) sc["model1d"]["model"] = "paper";  // read in paper mode only
    if (path == "model1d.axial_bending.rigidity") sc["model1d"]["axial_bending"]["source"] = "scene";  // read then only
    swim::scene::apply_override(sc, path + "=[1]");
    std::string msg;
    EXPECT_EQ(read1d_key(sc, &msg), path) << msg;
    EXPECT_EQ(msg.find("unknown key"), std::string::npos) << msg;
  }
  (void)junk;
}

// One scene, one validation: the range a section's schema states for a value is the range the
// owning tier's reader accepts. For every ranged leaf of the 3D and axisymmetric sections, a
// value just outside it is refused by the schema check (what a run of another tier applies)
// and by the owning reader, both naming the key; a 1D run refuses `full3d.dt = -1 ms`.
TEST(StrictScene, OtherTierValuesOutOfRangeAreRefusedAsByTheirOwnReader) {
  std::vector<std::pair<std::string, std::string>> keys;
  leaves(swim::full3d::section_keys(), "full3d", keys);
  leaves(swim::axi::section_keys(), "", keys);
  int ranged = 0;
  for (const auto& [path, kind] : keys) {
    const size_t at = kind.find('@');
    if (at == std::string::npos) continue;
    ++ranged;
    const std::string spec = kind.substr(at + 1), base = kind.substr(0, at);
    double bad = 0;
    if (spec == "positive") bad = 0.0;
    else if (spec == "non_negative") bad = -1.0;
    else {
      const double lo = std::stod(spec.substr(1, spec.find(',') - 1));
      bad = spec.front() == '(' ? lo : lo - 1.0;
    }
    json value;
    if (base.rfind("quantity:", 0) == 0) value = std::to_string(bad) + " " + base.substr(9);
    else if (base == "integer") value = static_cast<long>(bad);
    else value = bad;
    const bool axi = path.rfind("axi.", 0) == 0;
    // the axisymmetric tier reads round-wall scenes in the cylinder only
    json sc = axi ? swim::scene::load_file(SWIM_SOURCE_DIR "/data/scenes/paper_amplitude_0.82.json") : json::object();
    if (axi) sc["full3d"]["membrane"]["axisymmetric"] = true;
    json section = json::object();
    swim::scene::apply_override(section, path + "=" + value.dump());
    const std::string top = axi ? "axi" : "full3d";
    std::string msg;
    EXPECT_EQ(rejected_key([&] { swim::scene::check_section(section[top], top, axi ? swim::axi::section_keys()["axi"]
                                                                                     : swim::full3d::section_keys()); },
                           &msg),
              path)
        << value << ": " << msg;
    sc.merge_patch(section);
    json r;
    EXPECT_EQ(rejected_key([&] {
                if (axi) swim::axi::read_scene_axi(sc, r);
                else swim::full3d::read_scene3d(sc, r);
              }, &msg),
              path)
        << value << ": " << msg;
  }
  EXPECT_GE(ranged, 25);
  // a 1D run checks the 3D section's values, not only their kinds
  std::string msg;
  EXPECT_EQ(read1d_key(json::parse(R"({"full3d": {"dt": "-1 ms"}})"), &msg), "full3d.dt") << msg;
  EXPECT_NE(msg.find("must be > 0"), std::string::npos) << msg;
  EXPECT_EQ(read1d_key(json::parse(R"({"axi": {"grid": {"cells_across": 4}}})"), &msg), "axi.grid.cells_across") << msg;
}

// One scene, one validation: the shared sections (name, swimmer, fluid, container, wall, wave,
// protocol, time) are read by scene::SharedScene alone. A bad value in any of them is refused
// with the same message whether the shared reader, the 1D, the 3D or the axisymmetric tier
// reads the scene, and a good scene resolves to the same shared sections on every tier.
TEST(StrictScene, TheSharedSectionsAreReadOnceForEveryTier) {
  json base = swim::scene::load_file(SWIM_SOURCE_DIR "/data/scenes/demo.json");
  base["full3d"]["membrane"]["axisymmetric"] = true;  // a round wall in the cylinder: every tier reads it
  const auto shared = [](const json& sc) {
    json r = json::object();
    swim::scene::Reader top(sc, "", r);
    swim::scene::SharedScene s = swim::scene::SharedScene::read(top);
    s.read_protocol(top, swim::scene::c1_from_spring_constant(s.wall.value, s.body.R0));
    s.read_time(top);
    return r;
  };
  const std::vector<std::pair<std::string, std::vector<std::string>>> bad = {
      {"name", {"name=../x"}},
      {"swimmer.length", {"swimmer.length=0.4 s"}},
      {"swimmer.lenght", {"swimmer.lenght=0.4 um"}},
      {"fluid.temperature", {"fluid.temperature=20000 K"}},
      {"container.radius", {"container.radius=0.1 um"}},
      {"container.period", {"container.period=0.3 um"}},
      {"wall.stretching_modulus", {"wall.stretching_modulus=1 N/m"}},
      {"wall.mass_per_length", {"wall.mass_per_length=0 kg/m"}},
      {"wave.kind", {"wave.kind=square"}},
      {"wave.contracted_ratio", {"wave.contracted_ratio=1.5"}},
      {"wave.contracted_radius", {"wave.contracted_radius=0.2 um"}},
      {"protocol.segments", {"protocol.segments=1"}},
      {"protocol.total_force", {"protocol.total_force=1e-6 pN"}},
      {"protocol.tolerance_ratio", {"protocol.tolerance_ratio=0.5"}},
      {"protocol.foo", {"protocol.foo=1"}},
      {"time.duration", {"time.duration=0 s"}},
      {"time.duration", {"time.duration=5"}},
      {"time.output_interval", {"time.duration=10 ms", "time.output_interval=1 s"}},
      {"time.step", {"time.step=1 ms"}},
  };
  for (const auto& [key, sets] : bad) {
    json sc = base;
    for (const auto& s : sets) swim::scene::apply_override(sc, s);
    std::string own, m1, m3, ma;
    EXPECT_EQ(rejected_key([&] { shared(sc); }, &own), key) << own;
    EXPECT_EQ(rejected_key([&] { json r; swim::reduced1d::read_scene(sc, r); }, &m1), key) << m1;
    EXPECT_EQ(rejected_key([&] { json r; swim::full3d::read_scene3d(sc, r); }, &m3), key) << m3;
    EXPECT_EQ(rejected_key([&] { json r; swim::axi::read_scene_axi(sc, r); }, &ma), key) << ma;
    EXPECT_EQ(m1, own);
    EXPECT_EQ(m3, own);
    EXPECT_EQ(ma, own);
  }
  // a prescribed wave refuses the protocol section on the tiers that run it
  json step = base;
  swim::scene::apply_override(step, "wave.kind=step");
  std::string own, m1, ma;
  EXPECT_EQ(rejected_key([&] { shared(step); }, &own), "protocol") << own;
  EXPECT_EQ(rejected_key([&] { json r; swim::reduced1d::read_scene(step, r); }, &m1), "protocol") << m1;
  EXPECT_EQ(rejected_key([&] { json r; swim::axi::read_scene_axi(step, r); }, &ma), "protocol") << ma;
  EXPECT_EQ(m1, own);
  EXPECT_EQ(ma, own);
  // a good scene: the same values used for every shared key, on every tier
  const json s = shared(base);
  json r1, r3, ra;
  swim::reduced1d::read_scene(base, r1);
  swim::full3d::read_scene3d(base, r3);
  swim::axi::read_scene_axi(base, ra);
  for (const char* section : {"name", "description", "swimmer", "fluid", "container", "wall", "wave", "protocol", "time"}) {
    ASSERT_TRUE(s.contains(section)) << section;
    EXPECT_EQ(r1.at(section), s.at(section)) << section;
    EXPECT_EQ(r3.at(section), s.at(section)) << section;
    EXPECT_EQ(ra.at(section), s.at(section)) << section;
  }
}

// The tiers solve continuum Stokes flow: a tube radius or length below 1 nm (a mistyped unit,
// 1e-15 m for 1e-6 m) is exit 2 naming the key, the value and the least allowed, before
// anything is written; on every tier, since all read the shared swimmer section. Without the
// check the 1D demo at 1e-15 m stepped for minutes without reaching its first output time, and
// at 1e-12 m wrote a gigabyte of output before failing. 1 nm runs (the demo: a cycle in 2 s).
TEST(StrictScene, ATubeBelowTheContinuumScaleIsRejectedNamingTheKey) {
  const fs::path d = tmpdir("continuum");
  for (const auto& [key, value] : std::vector<std::pair<std::string, std::string>>{
           {"swimmer.radius", "1e-15 m"}, {"swimmer.radius", "0.5 nm"}, {"swimmer.length", "0.9 nm"}})
    for (const char* tier : {"1d", "3d", "axi"}) {
      const Cli c = swim_cli("run \"" + std::string(SWIM_SOURCE_DIR) + "/data/scenes/demo.json\" --tier " + tier +
                                 " --set " + key + "='\"" + value + "\"' --out \"" + (d / "out").string() + "\"",
                             d);
      EXPECT_EQ(c.code, 2) << key << " = " << value << " on " << tier << ": " << c.err;
      EXPECT_NE(c.err.find("'" + key + "'"), std::string::npos) << c.err;
      EXPECT_NE(c.err.find("at least 1 nm"), std::string::npos) << c.err;
      EXPECT_NE(c.err.find("continuum"), std::string::npos) << c.err;
      EXPECT_FALSE(fs::exists(d / "out")) << key << " on " << tier;
    }
  const Cli ok = swim_cli("run \"" + std::string(SWIM_SOURCE_DIR) + "/data/scenes/demo.json\" --set swimmer.radius='\"1 nm\"' --out \"" +
                              (d / "ok").string() + "\"",
                          d);
  EXPECT_EQ(ok.code, 0) << ok.err;
  fs::remove_all(d);
}
