//! Content-addressed file store for uploaded logs: `<dir>/<sha256>`. A blob
//! is streamed to a temporary file while hashing, fsynced, then renamed into
//! place — so an upload is on disk, verbatim and verified, before any row
//! refers to it or any parsing starts.

use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};
use tokio::fs::File;
use tokio::io::AsyncWriteExt;

/// The blob directory.
#[derive(Debug, Clone)]
pub struct BlobStore {
    dir: PathBuf,
}

/// A blob being written.
pub struct BlobWriter {
    file: File,
    tmp: PathBuf,
    hasher: Sha256,
    size: u64,
    dir: PathBuf,
}

/// A stored blob.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StoredBlob {
    /// Lower-case hex SHA-256 of the bytes.
    pub sha256: String,
    /// Size in bytes.
    pub size: u64,
}

impl BlobStore {
    /// Opens (creating) the store.
    pub fn open(dir: &Path) -> std::io::Result<Self> {
        std::fs::create_dir_all(dir.join("tmp"))?;
        Ok(BlobStore {
            dir: dir.to_path_buf(),
        })
    }

    /// Removes the partial uploads a stopped server left in `tmp/` (call
    /// it before serving); how many.
    pub fn sweep_tmp(&self) -> std::io::Result<usize> {
        let mut n = 0;
        for entry in std::fs::read_dir(self.dir.join("tmp"))? {
            let entry = entry?;
            if entry.file_type()?.is_file() {
                std::fs::remove_file(entry.path())?;
                n += 1;
            }
        }
        Ok(n)
    }

    /// The names of the stored blob files (their SHA-256), without `tmp/`.
    pub fn files(&self) -> std::io::Result<Vec<String>> {
        let mut names = Vec::new();
        for entry in std::fs::read_dir(&self.dir)? {
            let entry = entry?;
            let name = entry.file_name().to_string_lossy().into_owned();
            if entry.file_type()?.is_file()
                && name.len() == 64
                && name.bytes().all(|b| b.is_ascii_hexdigit())
            {
                names.push(name);
            }
        }
        Ok(names)
    }

    /// Path of a blob.
    pub fn path(&self, sha256: &str) -> PathBuf {
        self.dir.join(sha256)
    }

    /// Removes the file of a blob no run references any more (its row is
    /// already gone); a missing file is no error.
    pub async fn remove(&self, sha256: &str) -> std::io::Result<()> {
        match tokio::fs::remove_file(self.path(sha256)).await {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(e),
            _ => Ok(()),
        }
    }

    /// Starts writing a blob.
    pub async fn begin(&self) -> std::io::Result<BlobWriter> {
        let tmp = self.dir.join("tmp").join(uuid::Uuid::now_v7().to_string());
        Ok(BlobWriter {
            file: File::create(&tmp).await?,
            tmp,
            hasher: Sha256::new(),
            size: 0,
            dir: self.dir.clone(),
        })
    }
}

impl BlobWriter {
    /// Appends bytes.
    pub async fn write(&mut self, chunk: &[u8]) -> std::io::Result<()> {
        self.hasher.update(chunk);
        self.size += chunk.len() as u64;
        self.file.write_all(chunk).await
    }

    /// Bytes written so far.
    pub fn size(&self) -> u64 {
        self.size
    }

    /// Flushes, fsyncs and moves the blob into place under its hash.
    pub async fn finish(mut self) -> std::io::Result<StoredBlob> {
        self.file.flush().await?;
        self.file.sync_all().await?;
        drop(self.file);
        let sha256 = hex::encode(self.hasher.finalize());
        let dest = self.dir.join(&sha256);
        if tokio::fs::try_exists(&dest).await? {
            // Same bytes already stored: keep the first copy.
            tokio::fs::remove_file(&self.tmp).await?;
        } else {
            tokio::fs::rename(&self.tmp, &dest).await?;
        }
        Ok(StoredBlob {
            sha256,
            size: self.size,
        })
    }

    /// Discards a partial blob.
    pub async fn abort(self) {
        drop(self.file);
        let _ = tokio::fs::remove_file(&self.tmp).await;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[tokio::test]
    async fn blob_is_stored_verbatim_under_its_sha256() {
        let dir = tempfile::tempdir().unwrap();
        let store = BlobStore::open(dir.path()).unwrap();
        let mut w = store.begin().await.unwrap();
        w.write(b"t,u\n").await.unwrap();
        w.write(b"0,1\n").await.unwrap();
        let b = w.finish().await.unwrap();
        // sha256("t,u\n0,1\n") computed independently.
        assert_eq!(b.sha256, hex::encode(Sha256::digest(b"t,u\n0,1\n")));
        assert_eq!(b.size, 8);
        assert_eq!(std::fs::read(store.path(&b.sha256)).unwrap(), b"t,u\n0,1\n");
        // A second identical upload does not duplicate or fail.
        let mut w = store.begin().await.unwrap();
        w.write(b"t,u\n0,1\n").await.unwrap();
        assert_eq!(w.finish().await.unwrap(), b);
        assert_eq!(
            std::fs::read_dir(dir.path().join("tmp")).unwrap().count(),
            0
        );
    }
}
