"""Real servers and harnesses on 127.0.0.1 for the tests and the benchmarks (not shipped in any
image and imported by no production package): SFTP (OpenSSH ``sshd`` and asyncssh) and S3
(moto and SeaweedFS) servers, free ports, and the stub robot controller on an in-process world.
"""

__all__: list[str] = []  # tests import its modules; no product package imports it
