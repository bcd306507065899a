"""Real servers and harnesses on 127.0.0.1 for the tests and the benchmarks (not shipped in any
image and imported by no production package): SFTP (OpenSSH ``sshd`` and asyncssh) and S3
(moto and SeaweedFS) servers, free ports, the stub robot controller on an in-process world, and
the benchmarks' figures of the machine (targets, CPU steal, a busy neighbour CPU's cost).
"""

__all__: list[str] = []  # tests import its modules; no product package imports it
