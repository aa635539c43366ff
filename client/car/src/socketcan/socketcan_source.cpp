#include "dynid/car/socketcan_source.hpp"

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>

namespace dynid::car {
namespace {

using Clock = std::chrono::steady_clock;

template <typename T>
void set_option(int fd, int level, int option, const T& value, std::string_view interface_name,
                std::string_view what) {
  if (::setsockopt(fd, level, option, &value, sizeof(value)) != 0)
    throw SocketCanError(interface_name, what, errno);
}

std::string hex(std::uint32_t value) {
  char text[16];
  std::snprintf(text, sizeof(text), "0x%X", static_cast<unsigned>(value));
  return text;
}

std::vector<can_filter> kernel_filters(const std::vector<CanFilter>& filters,
                                       std::string_view interface_name) {
  std::vector<can_filter> out;
  for (const CanFilter& f : filters) {
    const std::uint32_t max = f.extended ? can::Frame::kMaxExtendedId : can::Frame::kMaxStandardId;
    if (f.id > max || f.mask > max)
      throw InputError("SocketCAN " + std::string(interface_name) + ": filter id/mask " +
                       hex(f.id) + "/" + hex(f.mask) + " does not fit a " +
                       (f.extended ? "29" : "11") + "-bit id");
    // CAN_EFF_FLAG in both id and mask makes the kernel compare the frame format too, so an
    // 11-bit filter never passes a 29-bit frame whose low bits happen to match.
    can_filter k{};
    k.can_id = f.id | (f.extended ? CAN_EFF_FLAG : 0U) | (f.inverted ? CAN_INV_FILTER : 0U);
    k.can_mask = f.mask | CAN_EFF_FLAG;
    out.push_back(k);
  }
  return out;
}

double seconds(const timespec& t) {
  return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}

// The kernel's receive timestamp from the control messages; the current time only if the kernel
// sent none (it always does once SO_TIMESTAMPNS is on, so this is a safety net, not a path).
double receive_time(msghdr& msg, std::uint64_t& dropped) {
  timespec stamp{};
  bool have_stamp = false;
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
    if (c->cmsg_level != SOL_SOCKET) continue;
    if (c->cmsg_type == SO_TIMESTAMPNS) {
      std::memcpy(&stamp, CMSG_DATA(c), sizeof(stamp));  // memcpy: CMSG_DATA is not aligned
      have_stamp = true;
    } else if (c->cmsg_type == SO_RXQ_OVFL) {
      std::uint32_t count = 0;
      std::memcpy(&count, CMSG_DATA(c), sizeof(count));
      dropped = count;
    }
  }
  if (!have_stamp) ::clock_gettime(CLOCK_REALTIME, &stamp);
  return seconds(stamp);
}

void fill_frame(const canfd_frame& raw, bool is_fd, can::Frame& frame) {
  frame.extended = (raw.can_id & CAN_EFF_FLAG) != 0;
  frame.id = raw.can_id & (frame.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
  frame.fd = is_fd;
  frame.rtr = !is_fd && (raw.can_id & CAN_RTR_FLAG) != 0;
  frame.fd_flags = is_fd ? static_cast<std::uint8_t>(raw.flags & (CANFD_BRS | CANFD_ESI)) : 0;
  const std::size_t max = is_fd ? can::Frame::kMaxFdData : can::Frame::kMaxClassicData;
  frame.length = static_cast<std::uint8_t>(std::min<std::size_t>(raw.len, max));
  frame.data.fill(0);
  // A remote frame's length is its requested DLC; it carries no bytes.
  if (!frame.rtr) std::copy_n(raw.data, frame.length, frame.data.begin());
}

}  // namespace

SocketCanSource::SocketCanSource(std::string interface_name, const SocketCanOptions& options)
    : interface_(std::move(interface_name)) {
  if (interface_.empty() || interface_.size() >= IFNAMSIZ ||
      interface_.find('/') != std::string::npos)
    throw InputError("SocketCAN: bad interface name '" + interface_ + "' (1 to " +
                     std::to_string(IFNAMSIZ - 1) + " characters, no '/')");
  const std::vector<can_filter> filters = kernel_filters(options.filters, interface_);

  socket_ = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (socket_ < 0) throw SocketCanError(interface_, "socket(PF_CAN, SOCK_RAW, CAN_RAW)", errno);
  try {
    configure(options);
    if (!filters.empty() &&
        ::setsockopt(socket_, SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(),
                     static_cast<socklen_t>(filters.size() * sizeof(can_filter))) != 0)
      throw SocketCanError(interface_, "setsockopt(CAN_RAW_FILTER)", errno);
    bind_interface();
    stop_event_ = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
    if (stop_event_ < 0) throw SocketCanError(interface_, "eventfd", errno);
  } catch (...) {
    close();
    throw;
  }
}

SocketCanSource::~SocketCanSource() { close(); }

void SocketCanSource::configure(const SocketCanOptions& options) {
  const int on = 1;
  set_option(socket_, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, on, interface_,
             "setsockopt(CAN_RAW_FD_FRAMES)");
  set_option(socket_, SOL_SOCKET, SO_TIMESTAMPNS, on, interface_, "setsockopt(SO_TIMESTAMPNS)");
  set_option(socket_, SOL_SOCKET, SO_RXQ_OVFL, on, interface_, "setsockopt(SO_RXQ_OVFL)");
  // Error frames are off by default; they are asked for only to be counted (bad_input()).
  const can_err_mask_t errors = CAN_ERR_MASK;
  set_option(socket_, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, errors, interface_,
             "setsockopt(CAN_RAW_ERR_FILTER)");
  if (options.receive_buffer_bytes > 0)
    set_option(socket_, SOL_SOCKET, SO_RCVBUF, options.receive_buffer_bytes, interface_,
               "setsockopt(SO_RCVBUF)");
}

void SocketCanSource::bind_interface() {
  const unsigned index = ::if_nametoindex(interface_.c_str());
  if (index == 0) throw SocketCanError(interface_, "if_nametoindex", errno);
  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = static_cast<int>(index);
  // bind() also rejects an interface that exists but is not a CAN device (ENODEV).
  if (::bind(socket_, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0)
    throw SocketCanError(interface_, "bind", errno);
}

void SocketCanSource::request_stop() noexcept {
  stop_.store(true);
  if (stop_event_ >= 0) {
    const std::uint64_t one = 1;
    [[maybe_unused]] const ssize_t n = ::write(stop_event_, &one, sizeof(one));
  }
}

void SocketCanSource::close() noexcept {
  stop_.store(true);
  if (socket_ >= 0) ::close(socket_);
  if (stop_event_ >= 0) ::close(stop_event_);
  socket_ = -1;
  stop_event_ = -1;
}

NextStatus SocketCanSource::next(can::Frame& frame, std::chrono::milliseconds timeout) {
  const Clock::time_point deadline = Clock::now() + std::max(timeout, std::chrono::milliseconds{0});
  while (!stop_.load() && socket_ >= 0) {
    switch (read_one(frame)) {
      case ReadResult::Frame:
        return NextStatus::Frame;
      case ReadResult::Skipped:
        continue;  // an error frame: counted, look for the next one within the same deadline
      case ReadResult::WouldBlock:
        if (!wait_readable(deadline)) return stop_.load() ? NextStatus::End : NextStatus::Timeout;
    }
  }
  return NextStatus::End;
}

// Reads once without blocking: the frames queued already are returned before poll() is asked.
SocketCanSource::ReadResult SocketCanSource::read_one(can::Frame& frame) {
  canfd_frame raw{};
  iovec io{&raw, sizeof(raw)};
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec)) + CMSG_SPACE(sizeof(std::uint32_t))];
  msghdr msg{};
  msg.msg_iov = &io;
  msg.msg_iovlen = 1;
  msg.msg_control = control;
  msg.msg_controllen = sizeof(control);

  const ssize_t n = ::recvmsg(socket_, &msg, MSG_DONTWAIT);
  if (n < 0) {
    if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) return ReadResult::WouldBlock;
    throw SocketCanError(interface_, "recvmsg", errno);
  }
  const double stamp = receive_time(msg, dropped_);
  const auto size = static_cast<std::size_t>(n);
  if (size != CAN_MTU && size != CANFD_MTU) {
    ++malformed_;
    return ReadResult::Skipped;
  }
  if ((raw.can_id & CAN_ERR_FLAG) != 0) {
    ++error_frames_;
    return ReadResult::Skipped;
  }
  fill_frame(raw, size == CANFD_MTU, frame);
  frame.timestamp = stamp;
  frame.set_interface_name(interface_);  // fits: the constructor checked the length
  ++frames_;
  return ReadResult::Frame;
}

// False at the deadline or on request_stop(); true when the socket has something to read.
bool SocketCanSource::wait_readable(Clock::time_point deadline) {
  pollfd fds[2] = {{socket_, POLLIN, 0}, {stop_event_, POLLIN, 0}};
  while (!stop_.load()) {
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now());
    if (left.count() <= 0) return false;
    const int ready = ::poll(fds, 2, static_cast<int>(std::min<long long>(left.count(), 60'000)));
    if (ready < 0 && errno != EINTR) throw SocketCanError(interface_, "poll", errno);
    if (ready > 0 && (fds[1].revents & POLLIN) != 0) return false;
    if (ready > 0 && fds[0].revents != 0) return true;  // data, or an error recvmsg will report
  }
  return false;
}

}  // namespace dynid::car
