/*
 * lbp16.c - Mesa's LBP16 protocol over UDP: the socket, building
 * packets of read and write commands, and the bounded exchange.
 *
 * A command is a 16-bit little-endian word (write flag, address flag,
 * memory space, transfer size, address increment, count), then the
 * 16-bit address, then for a write the data.  A packet may hold several
 * commands; the card answers a packet that has reads with one datagram
 * holding the data of every read, in order.  Writes are not answered.
 *
 * Nothing here allocates; lbp16_send, lbp16_recv and lbp16_drain are
 * what the thread functions use, and every wait has a deadline.
 */
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "hm2.h"

static long long now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1000000000LL + ts.tv_nsec;
}

/* board_ip is "a.b.c.d" (port 27181) or "a.b.c.d:port" (a simulated
   card on another port).  Returns 0 or a negative errno. */
int lbp16_open(struct lbp16_link *l, const char *board_ip)
{
    char host[48];
    const char *colon = strchr(board_ip, ':');
    long port = HM2_PORT;
    struct sockaddr_in sa;
    int fd, flags;

    l->fd = -1;
    snprintf(l->where, sizeof(l->where), "%s", board_ip);
    if (colon) {
        char *end;
        size_t n = (size_t)(colon - board_ip);
        if (n >= sizeof(host))
            return -EINVAL;
        memcpy(host, board_ip, n);
        host[n] = 0;
        port = strtol(colon + 1, &end, 10);
        if (*end || port < 1 || port > 65535)
            return -EINVAL;
    } else {
        if (strlen(board_ip) >= sizeof(host))
            return -EINVAL;
        strcpy(host, board_ip);
    }
    memset(&sa, 0, sizeof(sa));
    sa.sin_family = AF_INET;
    sa.sin_port = htons((unsigned short)port);
    if (inet_pton(AF_INET, host, &sa.sin_addr) != 1)
        return -EINVAL;
    snprintf(l->where, sizeof(l->where), "%s:%ld", host, port);
    fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd < 0)
        return -errno;
    if (connect(fd, (struct sockaddr *)&sa, sizeof(sa)) < 0) {
        int e = errno;
        close(fd);
        return -e;
    }
    flags = fcntl(fd, F_GETFL);
    if (flags < 0 || fcntl(fd, F_SETFL, flags | O_NONBLOCK) < 0) {
        int e = errno;
        close(fd);
        return -e;
    }
    l->fd = fd;
    return 0;
}

void lbp16_close(struct lbp16_link *l)
{
    if (l->fd >= 0)
        close(l->fd);
    l->fd = -1;
}

void lbp16_pkt_reset(struct lbp16_pkt *p)
{
    p->len = 0;
    p->reply = 0;
    p->full = 0;
}

static void put16(u8 *b, unsigned v)
{
    b[0] = v & 0xff;
    b[1] = (v >> 8) & 0xff;
}

/* append a read of count words (32-bit if size32, else 16-bit) from
   addr in space, address incrementing */
int lbp16_pkt_read(struct lbp16_pkt *p, int space, int size32, u16 addr,
                   int count)
{
    int bytes = count * (size32 ? 4 : 2);
    if (count < 1 || count > LBP16_COUNT_MAX || p->len + 4 > HM2_PKT_MAX
        || p->reply + bytes > HM2_PKT_MAX) {
        p->full = 1;
        return -ENOSPC;
    }
    put16(p->buf + p->len, LBP16_ADDR | LBP16_SPACE(space)
          | (size32 ? LBP16_SIZE_32 : LBP16_SIZE_16) | LBP16_INC | count);
    put16(p->buf + p->len + 2, addr);
    p->len += 4;
    p->reply += bytes;
    return 0;
}

/* append a write of count 32-bit words to addr in the HostMot2 space */
int lbp16_pkt_write32(struct lbp16_pkt *p, u16 addr, const u32 *data,
                      int count)
{
    int i;
    if (count < 1 || count > LBP16_COUNT_MAX
        || p->len + 4 + 4 * count > HM2_PKT_MAX) {
        p->full = 1;
        return -ENOSPC;
    }
    put16(p->buf + p->len, LBP16_WRITE | LBP16_ADDR
          | LBP16_SPACE(LBP16_SPACE_HM2) | LBP16_SIZE_32 | LBP16_INC | count);
    put16(p->buf + p->len + 2, addr);
    p->len += 4;
    for (i = 0; i < count; i++) {
        u32 v = data[i];
        p->buf[p->len++] = v & 0xff;
        p->buf[p->len++] = (v >> 8) & 0xff;
        p->buf[p->len++] = (v >> 16) & 0xff;
        p->buf[p->len++] = (v >> 24) & 0xff;
    }
    return 0;
}

/* send one packet; 0 or a negative errno (the socket never blocks) */
int lbp16_send(struct lbp16_link *l, const struct lbp16_pkt *p)
{
    ssize_t r;
    if (p->len == 0)
        return 0;
    r = send(l->fd, p->buf, (size_t)p->len, MSG_DONTWAIT);
    if (r < 0)
        return -errno;
    return r == p->len ? 0 : -EIO;
}

/* throw away datagrams already queued: late replies to earlier reads */
void lbp16_drain(struct lbp16_link *l)
{
    u8 junk[64];
    int i;
    for (i = 0; i < 64; i++)
        if (recv(l->fd, junk, sizeof(junk), MSG_DONTWAIT) < 0
            && errno != ECONNREFUSED)
            return;
}

/* wait at most timeout_ns for one datagram of exactly want bytes.
   Returns want, -ETIMEDOUT, -EPROTO (a datagram of another size),
   -ECONNREFUSED (nothing listens: loopback) or another negative errno */
int lbp16_recv(struct lbp16_link *l, u8 *buf, int want, long timeout_ns)
{
    long long deadline = now_ns() + timeout_ns;
    for (;;) {
        ssize_t r = recv(l->fd, buf, HM2_PKT_MAX, MSG_DONTWAIT);
        long long left;
        struct pollfd pfd;
        struct timespec ts;
        if (r >= 0)
            return r == want ? want : -EPROTO;
        if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)
            return -errno;
        left = deadline - now_ns();
        if (left <= 0)
            return -ETIMEDOUT;
        pfd.fd = l->fd;
        pfd.events = POLLIN;
        ts.tv_sec = left / 1000000000LL;
        ts.tv_nsec = left % 1000000000LL;
        ppoll(&pfd, 1, &ts, NULL);
    }
}

/* load time: send p and wait for its reply, retrying lost packets */
int lbp16_transact(struct lbp16_link *l, const struct lbp16_pkt *p, u8 *buf,
                   long timeout_ns, int tries)
{
    int r = -ETIMEDOUT, i;
    for (i = 0; i < tries; i++) {
        lbp16_drain(l);
        r = lbp16_send(l, p);
        if (r < 0)
            return r;
        if (p->reply == 0)
            return 0;
        r = lbp16_recv(l, buf, p->reply, timeout_ns);
        if (r >= 0 || r == -ECONNREFUSED)
            return r;
    }
    return r;
}

#define LOAD_TIMEOUT_NS 200000000L  /* 0.2 s per try at load time */
#define LOAD_TRIES 5

static u32 get32(const u8 *b)
{
    return (u32)b[0] | ((u32)b[1] << 8) | ((u32)b[2] << 16)
        | ((u32)b[3] << 24);
}

/* load time: read count words of the HostMot2 space */
int lbp16_read32(struct lbp16_link *l, u16 addr, u32 *dst, int count)
{
    struct lbp16_pkt p;
    u8 buf[HM2_PKT_MAX];
    while (count > 0) {
        int n = count > 64 ? 64 : count, i, r;
        lbp16_pkt_reset(&p);
        lbp16_pkt_read(&p, LBP16_SPACE_HM2, 1, addr, n);
        r = lbp16_transact(l, &p, buf, LOAD_TIMEOUT_NS, LOAD_TRIES);
        if (r < 0)
            return r;
        for (i = 0; i < n; i++)
            dst[i] = get32(buf + 4 * i);
        dst += n;
        addr += 4 * n;
        count -= n;
    }
    return 0;
}

int lbp16_write32(struct lbp16_link *l, u16 addr, const u32 *src, int count)
{
    struct lbp16_pkt p;
    lbp16_pkt_reset(&p);
    if (lbp16_pkt_write32(&p, addr, src, count) < 0)
        return -ENOSPC;
    return lbp16_send(l, &p);
}

/* load time: the count of datagrams the card has received (this one
   included) */
int lbp16_rx_count(struct lbp16_link *l, u16 *count)
{
    struct lbp16_pkt p;
    u8 buf[HM2_PKT_MAX];
    int r;
    lbp16_pkt_reset(&p);
    lbp16_pkt_read(&p, LBP16_SPACE_COMM, 0, COMM_RX_COUNT, 1);
    r = lbp16_transact(l, &p, buf, LOAD_TIMEOUT_NS, LOAD_TRIES);
    if (r < 0)
        return r;
    *count = (u16)(buf[0] | (buf[1] << 8));
    return 0;
}

/* the card's name from the board-information space ("7I96S"), as a
   NUL-terminated string */
int lbp16_board_name(struct lbp16_link *l, char *name, int len)
{
    struct lbp16_pkt p;
    u8 buf[HM2_PKT_MAX];
    int r, i;
    lbp16_pkt_reset(&p);
    lbp16_pkt_read(&p, LBP16_SPACE_INFO, 0, 0, 8);
    r = lbp16_transact(l, &p, buf, LOAD_TIMEOUT_NS, LOAD_TRIES);
    if (r < 0)
        return r;
    for (i = 0; i < 16 && i < len - 1; i++) {
        char c = (char)buf[i];
        if (c == 0 || c == ' ')
            break;
        name[i] = c;
    }
    name[i] = 0;
    return 0;
}
