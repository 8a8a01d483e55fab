// The tire rig's job (study/tire_job, codyna tire and the GUI's Tire tab): the loads it takes when
// none are given, decided there for every front end: a .tir's 0.5, 1 and 1.5 times FNOMIN; a
// linear or Fiala tire's typical 2, 4 and 6 kN when the front end asks for them (the GUI draws
// curves at once), refused naming --load otherwise (the command line); the forces are the law's.
#include "study/tire_job.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "vehicle/tir_file.hpp"

namespace codyna {
namespace {

int rig_column(const TireJob& j, const std::string& name) {
  for (std::size_t k = 0; k < j.columns.size(); ++k)
    if (j.columns[k] == name) return static_cast<int>(k);
  ADD_FAILURE() << "no column " << name;
  return 0;
}

TEST(TireJob, LoadsWhenNoneAreGiven) {
  TireRequest r;
  r.model = CODYNA_EXAMPLES_DIR "/single_track_car.json";
  r.tire = "front_tire";
  r.alpha = {0.01};
  try {
    study_tire_job(r);
    ADD_FAILURE() << "a linear tire without loads was not refused";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "--load: give the loads (N) for a linear tire");
  }
  r.typical_loads = true;
  const TireJob lin = study_tire_job(r);
  ASSERT_EQ(lin.rows.rows(), 3);
  const int fz = rig_column(lin, "Fz"), fy = rig_column(lin, "Fy");
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(lin.rows(i, fz), 2000.0 * (i + 1));
    EXPECT_NEAR(lin.rows(i, fy), -160000 * 0.01, 1e-9);  // the file's cornering stiffness, Fy = -C alpha
  }
  // a .tir: its nominal load's multiples, typical_loads or not
  TireRequest t;
  t.tir = CODYNA_EXAMPLES_DIR "/tires/MagicFormula61_Paramerters.tir";
  t.typical_loads = true;
  const TireJob mf = study_tire_job(t);
  const double fnomin = read_tir_file(t.tir).FNOMIN;
  ASSERT_EQ(mf.rows.rows(), 3);
  for (int i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(mf.rows(i, rig_column(mf, "Fz")), fnomin * (0.5 + 0.5 * i));
  // given loads win
  r.loads = {1234.5};
  EXPECT_EQ(study_tire_job(r).rows(0, fz), 1234.5);
}

}  // namespace
}  // namespace codyna
