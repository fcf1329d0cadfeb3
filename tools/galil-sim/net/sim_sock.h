/*
 * sim_sock.h - galil-sim's socket helpers: a TCP listener on 127.0.0.1 and
 * the non-blocking settings every socket of the simulator gets.
 *
 * It is not a protocol: the Galil command port is sim_cmdport.h, the
 * control port sim_ctlport.h. Nothing here prints.
 */
#ifndef SIM_SOCK_H
#define SIM_SOCK_H

#include <stddef.h>

/*
 * sim_sock_listen() - a TCP socket bound to @addr:@port (0 = any free
 * port), listening (backlog 16), non-blocking and close-on-exec.
 * @addr: a dotted IPv4 address ("0.0.0.0" = every interface), or NULL for
 *        127.0.0.1.
 * @bound: [out] the port number bound.
 * @err: [out] e.g. "cannot listen on 127.0.0.1:23023: Address already in
 *       use"; @errlen its size.
 * Return: the socket (>= 0, owned by the caller, close() it), or
 *         GL_ERR_SYS.
 */
int sim_sock_listen(const char *addr, int port, int *bound, char *err,
		    size_t errlen);

/* sim_sock_nonblock() - make @fd non-blocking and close-on-exec. */
void sim_sock_nonblock(int fd);

/*
 * sim_sock_again() - 1 when @err (an errno after recv() or send()) means
 * "try again later" (EAGAIN, EWOULDBLOCK, EINTR), else 0.
 */
int sim_sock_again(int err);

#endif /* SIM_SOCK_H */
