// test_cli_outputs.cpp - where `collide solve` writes its results: regular
// files (renamed temporaries), stdout ("-"), character devices and FIFOs
// (written in place, never replaced) - collide/io/output_file.hpp.
//
// What this proves
// ----------------
// * `--out-bodies -` puts exactly the bytes of a regular output on stdout;
//   both outputs '-' is a usage error (exit 2) that writes nothing.
// * A private character device made with mknod in the test's directory (a
//   null device, major 1 minor 3; /dev itself is never touched) stays a
//   character device with the same device number after a solve writes to
//   it, and no temporary is left next to it. Where mknod is not permitted
//   the test says so and skips.
// * Both outputs may go to one null device; a link into /proc (as
//   /dev/stdout is; the test makes its own) is written in place, not
//   replaced, even when stdout is a regular file;
//   a symbolic link to a regular file stays a link and its file is replaced.
// * A FIFO gets the data (a reader thread receives the same bytes a regular
//   file gets) and is still a FIFO afterwards.
// * Bad input opens no output: a FIFO held open by a reader receives no
//   byte, and the writer never opened it.
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "support/run_cli.hpp"

namespace fs = std::filesystem;

namespace {

using collide::test::RunResult;
using collide::test::slurp;

const char* const kBodies =
    "m,Ix,Iy,Iz,qw,qx,qy,qz,px,py,pz,vx,vy,vz,wx,wy,wz\n"
    "2,0.8,0.8,0.8,1,0,0,0,0,1,0,0.5,-3,0,0,0,1\n"
    "1.5,0.2,0.6,0.6,0.9238795325112867,0,0,0.3826834323650898,0.8,2.2,0,-0.5,-4,0,0,0,-2\n"
    "inf,inf,inf,inf,1,0,0,0,0,-5,0,0,0,0,0,0,0\n";

const char* const kContacts =
    "a,b,cx,cy,cz,nx,ny,nz,e,mu\n"
    "0,2,0,0,0,0,1,0,0.5,0.4\n"
    "1,0,0.4,1.6,0,0,1,0,0.8,0\n";

class OutputTargetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(COLLIDE_TEST_TMP) / (std::string(info->test_suite_name()) + "." + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    write_text(path("bodies.csv"), kBodies);
    write_text(path("contacts.csv"), kContacts);
  }

  static void write_text(const fs::path& p, const std::string& text) {
    std::ofstream out(p, std::ios::binary);
    out << text;
  }

  fs::path path(const std::string& name) const { return dir_ / name; }

  RunResult solve(const std::string& out_bodies, const std::string& out_impulses,
                  const std::string& bodies = "bodies.csv") const {
    return collide::test::run_program(
        COLLIDE_CLI_PATH, dir_,
        {"solve", "--bodies", path(bodies).string(), "--contacts", path("contacts.csv").string(), "--out-bodies",
         out_bodies, "--out-impulses", out_impulses});
  }

  /// The outputs of a solve into regular files: what every target must get.
  void reference_outputs(std::string& bodies, std::string& impulses) const {
    const RunResult r = solve(path("ref_b.csv").string(), path("ref_j.csv").string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    bodies = slurp(path("ref_b.csv"));
    impulses = slurp(path("ref_j.csv"));
    ASSERT_EQ(bodies.rfind("m,Ix,", 0), 0U);
    ASSERT_EQ(impulses.rfind("jx,jy,jz\n", 0), 0U);
  }

  /// Names in the test directory that look like a leftover temporary.
  std::vector<std::string> temporaries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) {
      const std::string n = e.path().filename().string();
      if (n.find(".tmp-") != std::string::npos) names.push_back(n);
    }
    return names;
  }

  fs::path dir_;
};

TEST_F(OutputTargetTest, DashIsStdout) {
  std::string bodies, impulses;
  reference_outputs(bodies, impulses);
  const RunResult r = solve("-", path("oj.csv").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, bodies);
  EXPECT_EQ(slurp(path("oj.csv")), impulses);
  EXPECT_FALSE(fs::exists(path("-")));

  const RunResult s = solve(path("ob.csv").string(), "-");
  ASSERT_EQ(s.exit_code, 0) << s.err;
  EXPECT_EQ(s.out, impulses);
  EXPECT_EQ(slurp(path("ob.csv")), bodies);
  EXPECT_TRUE(temporaries().empty());
}

TEST_F(OutputTargetTest, BothOnStdoutIsAUsageError) {
  const RunResult r = solve("-", "-");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("only one of --out-bodies and --out-impulses can be '-'"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
}

TEST_F(OutputTargetTest, CharacterDeviceIsWrittenNotReplaced) {
  const fs::path node = path("null");
  if (::mknod(node.c_str(), S_IFCHR | 0666, ::makedev(1, 3)) != 0) {
    GTEST_SKIP() << "mknod of a private character device (1, 3) is not permitted here (" << std::strerror(errno)
                 << "); the device case is untested here";
  }
  struct stat before {};
  ASSERT_EQ(::stat(node.c_str(), &before), 0);
  ASSERT_TRUE(S_ISCHR(before.st_mode));
  std::string bodies, impulses;
  reference_outputs(bodies, impulses);

  // --out-impulses DEVICE, and the device as the other output too.
  for (int which = 0; which < 2; ++which) {
    const RunResult r =
        which == 0 ? solve(path("ob.csv").string(), node.string()) : solve(node.string(), path("oj.csv").string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    struct stat after {};
    ASSERT_EQ(::lstat(node.c_str(), &after), 0);
    EXPECT_TRUE(S_ISCHR(after.st_mode)) << "the device node was replaced";
    EXPECT_EQ(after.st_rdev, before.st_rdev);
    EXPECT_EQ(after.st_ino, before.st_ino);
    EXPECT_TRUE(temporaries().empty());
  }
  EXPECT_EQ(slurp(path("ob.csv")), bodies);
  EXPECT_EQ(slurp(path("oj.csv")), impulses);

  // Both outputs into the one null device: allowed, nothing replaced.
  const RunResult both = solve(node.string(), node.string());
  ASSERT_EQ(both.exit_code, 0) << both.err;
  struct stat after {};
  ASSERT_EQ(::lstat(node.c_str(), &after), 0);
  EXPECT_TRUE(S_ISCHR(after.st_mode));
  EXPECT_TRUE(temporaries().empty());
}

TEST_F(OutputTargetTest, LinkToTheStdoutDescriptorIsWrittenInPlace) {
  // /dev/stdout is a link to /proc/self/fd/1; with stdout redirected to a
  // regular file (run_program does that) a rename would replace the link and
  // the redirection would never see the data. A private link of the same
  // kind stands in for /dev/stdout, so a failure cannot touch /dev.
  std::string bodies, impulses;
  reference_outputs(bodies, impulses);
  fs::create_symlink("/proc/self/fd/1", path("stdout"));
  const RunResult r = solve(path("ob.csv").string(), path("stdout").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, impulses);
  EXPECT_TRUE(fs::is_symlink(path("stdout"))) << "the link was replaced";
  EXPECT_TRUE(temporaries().empty());
}

TEST_F(OutputTargetTest, SymlinkToARegularFileStaysALink) {
  std::string bodies, impulses;
  reference_outputs(bodies, impulses);
  write_text(path("target.csv"), "old\n");
  fs::create_symlink("target.csv", path("link.csv"));
  const RunResult r = solve(path("ob.csv").string(), path("link.csv").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::is_symlink(path("link.csv")));
  EXPECT_EQ(slurp(path("target.csv")), impulses);
  EXPECT_TRUE(temporaries().empty());
}

TEST_F(OutputTargetTest, FifoGetsTheDataAndStaysAFifo) {
  const fs::path fifo = path("pipe");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  std::string bodies, impulses;
  reference_outputs(bodies, impulses);

  std::string received;
  std::thread reader([&] {
    std::ifstream in(fifo, std::ios::binary);  // blocks until the writer opens
    received.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  });
  const RunResult r = solve(path("ob.csv").string(), fifo.string());
  reader.join();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(received, impulses);
  EXPECT_EQ(slurp(path("ob.csv")), bodies);
  struct stat st {};
  ASSERT_EQ(::lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode)) << "the FIFO was replaced";
  EXPECT_TRUE(temporaries().empty());
}

TEST_F(OutputTargetTest, BadInputOpensNoDirectOutput) {
  const fs::path fifo = path("pipe");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  // A reader that does not block: a writer could open the FIFO and write
  // into its buffer without anyone reading.
  const int fd = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(fd, 0) << std::strerror(errno);
  write_text(path("bad.csv"),
             "m,Ix,Iy,Iz,qw,qx,qy,qz,px,py,pz,vx,vy,vz,wx,wy,wz\n"
             "-2,0.8,0.8,0.8,1,0,0,0,0,1,0,0.5,-3,0,0,0,1\n"
             "1.5,0.2,0.6,0.6,1,0,0,0,0.8,2.2,0,-0.5,-4,0,0,0,-2\n"
             "inf,inf,inf,inf,1,0,0,0,0,-5,0,0,0,0,0,0,0\n");
  const RunResult r = solve("-", fifo.string(), "bad.csv");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("bad.csv:2"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  char buf[64];
  EXPECT_EQ(::read(fd, buf, sizeof buf), 0) << "bytes reached the FIFO";
  ::close(fd);
  EXPECT_TRUE(temporaries().empty());
}

}  // namespace
