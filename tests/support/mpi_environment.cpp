// Every test executable runs inside MPI (the engine always works on a communicator):
// serial tests as an MPI singleton, *_mpi_test executables under mpirun. MPI starts in
// the environment's SetUp, not at load time, so that `--gtest_list_tests` (run by CTest
// at build time, outside mpirun) needs no MPI.
#include <gtest/gtest.h>
#include <mpi.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

namespace {

class MpiEnvironment : public ::testing::Environment {
 public:
  void SetUp() override {
    int initialised = 0;
    MPI_Initialized(&initialised);
    if (!initialised) {
      // The tests' transport, ob1, unless the environment names one (tests/CMakeLists.txt,
      // GRAINFLOW_TEST_MPI_TRANSPORT: a process starts in 0.12 s instead of 0.32 s).
      setenv("OMPI_MCA_pml", "ob1", /*overwrite=*/0);
      if (!std::getenv("OMPI_COMM_WORLD_SIZE") && !std::getenv("OMPI_MCA_orte_tmpdir_base")) {
        // A singleton (no mpirun): without Open MPI's daemon, 0.03 s instead of 0.12 s. Such
        // singletons all take one name and one session directory, which one that ends
        // removes while another makes it (tests/support/singleton.py): this one gets a base
        // of its own, removed at the end.
        std::error_code no_tmp;
        std::string base =
            (std::filesystem::temp_directory_path(no_tmp) / "grainflow-test-ompi-XXXXXX").string();
        if (!no_tmp && mkdtemp(base.data())) {
          session_base_ = base;
          setenv("OMPI_MCA_orte_tmpdir_base", base.c_str(), 1);
          setenv("OMPI_MCA_ess_singleton_isolated", "1", 1);
        }
      }
      MPI_Init(nullptr, nullptr);
      owner_ = true;
    }
  }
  void TearDown() override {
    int finalised = 0;
    MPI_Finalized(&finalised);
    if (owner_ && !finalised) MPI_Finalize();
    if (!session_base_.empty()) {
      std::error_code ignored;
      std::filesystem::remove_all(session_base_, ignored);
    }
  }

 private:
  bool owner_ = false;
  std::string session_base_;  // the singleton's own session directory base, or empty
};

[[maybe_unused]] auto* const environment =
    ::testing::AddGlobalTestEnvironment(new MpiEnvironment);

}  // namespace
