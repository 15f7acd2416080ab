merge -o merged.png shard.shard0of2.exr shard.shard1of2.exr
