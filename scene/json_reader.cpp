#include "scene/json_reader.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "scene/scene_keys.hpp"

namespace flexmbd::jsonread {

std::string readSceneFile(const std::string& path) {
  // the path as messages show it: a 100 KB path (refused by the system) keeps them one line
  constexpr std::size_t kMaxQuotedPath = 300;
  const std::string shown = shorten(path, kMaxQuotedPath);
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    throw InputError("cannot open scene file '" + shown + "': " +
                     (errno == ENOENT ? std::string("no such file") : std::strerror(errno)));
  }
  if (S_ISDIR(st.st_mode)) throw InputError("cannot read scene file '" + shown + "': it is a directory");
  if (!S_ISREG(st.st_mode)) {
    const char* kind = S_ISFIFO(st.st_mode)  ? "a FIFO (named pipe)"
                       : S_ISCHR(st.st_mode) ? "a character device (an endless or special file such as /dev/zero)"
                       : S_ISSOCK(st.st_mode) ? "a socket"
                                              : "not a regular file";
    throw InputError("cannot read scene file '" + shown + "': it is " + kind +
                     "; a scene must be a regular file (of at most 64 MiB)");
  }
  auto tooLarge = [&](std::uintmax_t bytes) {
    return InputError("scene file '" + shown + "' is " + std::to_string(bytes) + " bytes, more than the limit of " +
                      std::to_string(kMaxSceneFileBytes) + " bytes (64 MiB) for a scene file");
  };
  if (static_cast<std::uintmax_t>(st.st_size) > kMaxSceneFileBytes) throw tooLarge(st.st_size);
  // O_NONBLOCK: a file that became a FIFO after the check does not block the open
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) throw InputError("cannot open scene file '" + shown + "' for reading: " + std::strerror(errno));
  std::string text;
  char buf[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      ::close(fd);
      throw InputError("cannot read scene file '" + shown + "': " + std::strerror(err));
    }
    if (n == 0) break;
    text.append(buf, static_cast<std::size_t>(n));
    if (text.size() > kMaxSceneFileBytes) {  // a file that grows while it is read
      ::close(fd);
      throw tooLarge(text.size());
    }
  }
  ::close(fd);
  return text;
}

TimeLawPtr parseTimeLaw(const json& j, const std::string& where) {
  ObjectReader r(j, where);
  const std::string type =
      readType(r, "law", {"constant", "constant_speed", "polynomial", "harmonic", "spin_up", "tabulated"});
  const std::string forA = " for a " + type + " law";
  if (type == "constant") {
    r.allowOnly(scenekeys::kLawConstant, forA);
    const double value = r.number("value");
    return located(where, [&] { return makeConstantLaw(value); });
  }
  if (type == "constant_speed") {
    r.allowOnly(scenekeys::kLawConstantSpeed, forA);
    const double speed = r.number("speed");
    const double initial = r.number("initial", 0.0);
    return located(where, [&] { return makeConstantSpeedLaw(speed, initial); });
  }
  if (type == "polynomial") {
    r.allowOnly(scenekeys::kLawPolynomial, forA);
    std::vector<double> c = r.numbers("coefficients");
    return located(where, [&] { return makePolynomialLaw(std::move(c)); });
  }
  if (type == "harmonic") {
    r.allowOnly(scenekeys::kLawHarmonic, forA);
    const double amplitude = r.number("amplitude");
    const double omega = r.number("omega");
    const double phase = r.number("phase", 0.0);
    const double offset = r.number("offset", 0.0);
    return located(where, [&] { return makeHarmonicLaw(amplitude, omega, phase, offset); });
  }
  if (type == "spin_up") {
    r.allowOnly(scenekeys::kLawSpinUp, forA);
    const double speed = r.number("speed");
    const double rampTime = r.positive("ramp_time");
    const double initial = r.number("initial", 0.0);
    return located(where, [&] { return makeSpinUpLaw(speed, rampTime, initial); });
  }
  // tabulated
  r.allowOnly(scenekeys::kLawTabulated, forA);
  std::vector<double> times = r.numbers("times");
  std::vector<double> values = r.numbers("values");
  if (times.size() != values.size()) {
    r.fail("keys \"times\" and \"values\" must have the same length, got " + std::to_string(times.size()) +
           " and " + std::to_string(values.size()));
  }
  return located(where, [&] { return makeTabulatedLaw(std::move(times), std::move(values)); });
}

}  // namespace flexmbd::jsonread
