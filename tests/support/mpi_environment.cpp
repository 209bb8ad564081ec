// Every test executable runs inside MPI (the engine always works on a communicator):
// serial tests as an MPI singleton, *_mpi_test executables under mpirun. MPI starts in
// the environment's SetUp, not at load time, so that `--gtest_list_tests` (run by CTest
// at build time, outside mpirun) needs no MPI.
#include <gtest/gtest.h>
#include <mpi.h>

namespace {

class MpiEnvironment : public ::testing::Environment {
 public:
  void SetUp() override {
    int initialised = 0;
    MPI_Initialized(&initialised);
    if (!initialised) {
      MPI_Init(nullptr, nullptr);
      owner_ = true;
    }
  }
  void TearDown() override {
    int finalised = 0;
    MPI_Finalized(&finalised);
    if (owner_ && !finalised) MPI_Finalize();
  }

 private:
  bool owner_ = false;
};

[[maybe_unused]] auto* const environment =
    ::testing::AddGlobalTestEnvironment(new MpiEnvironment);

}  // namespace
